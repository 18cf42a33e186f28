"""The course's algorithms on the bundled mazes behave as the course says they do."""

import json

import pytest

from workbench.cli import main
from workbench.control.evaluate import evaluate
from workbench.control.headless import AlgorithmPilot, RunSetupError, RunSpec, run

ALL = [
    "right-wall",
    "farthest-distance",
    "one-distance-first",
    "first-working-solution",
    "two-distance-local-best",
    "self-adjusting-wall",
]


def result(maze, algorithm, profile="erobotic", **kw):
    return run(RunSpec(f"mazes/{maze}.txt", AlgorithmPilot(algorithm), profile=profile, **kw))


@pytest.mark.parametrize("profile", ["erobotic", "unity", "web"])
@pytest.mark.parametrize("algorithm", ALL)
def test_every_algorithm_gets_out_of_the_erobotic_maze(profile, algorithm):
    out = result("erobotic", algorithm, profile, noise="off").as_dict()
    assert out["reached_exit"], out
    assert out["collisions"] == 0


def test_farthest_distance_finds_the_exit_sooner_than_right_wall_on_the_erobotic_maze():
    wall = result("erobotic", "right-wall").as_dict()
    farthest = result("erobotic", "farthest-distance").as_dict()
    assert farthest["sim_time"] < wall["sim_time"]
    assert farthest["turn_degrees"] < wall["turn_degrees"]
    assert farthest["distance"] < wall["distance"]


def test_the_trap_maze_traps_right_wall_following_until_the_limit():
    trapped = result("trap-loop", "right-wall", max_time=300)
    assert not trapped.as_dict()["reached_exit"]
    assert trapped.cut_by_limit and trapped.as_dict()["sim_time"] == pytest.approx(300)
    assert result("trap-loop", "farthest-distance").as_dict()["reached_exit"]


def test_rankings_differ_between_the_ranking_mazes():
    ranked = evaluate(
        ["mazes/rank-wall-wins.txt", "mazes/rank-local-best-wins.txt"],
        ["right-wall", "farthest-distance", "two-distance-local-best"],
        seeds=1,
        profile="erobotic",
        jobs=1,
    )
    best = {m: ranked.ranking(m)[0].algorithm for m in ranked.mazes}
    assert best == {
        "mazes/rank-wall-wins.txt": "right-wall",
        "mazes/rank-local-best-wins.txt": "two-distance-local-best",
    }


@pytest.mark.parametrize(
    ("maze", "algorithm"), [("web", "web-wall-following"), ("web", "web-two-distance")]
)
def test_web_simulator_programs_get_out_on_the_web_profile(maze, algorithm):
    out = result(maze, algorithm, profile="web", noise="off").as_dict()
    assert out["reached_exit"], out


def test_realistic_motors_hurt_plain_wall_following_more_than_self_adjusting():
    kwargs = dict(seeds=4, profile="web", noise="realistic", jobs=1)
    ranked = evaluate(["mazes/erobotic.txt"], ["right-wall", "self-adjusting-wall"], **kwargs)
    plain = ranked.cell("mazes/erobotic.txt", "right-wall")
    adjusting = ranked.cell("mazes/erobotic.txt", "self-adjusting-wall")
    assert plain.mean["collisions"] > adjusting.mean["collisions"]
    assert plain.mean["distance_cells"] > adjusting.mean["distance_cells"]
    assert adjusting.reached == adjusting.runs


def test_same_seed_same_json_and_different_seed_different_trajectory(tmp_path, capsys):
    args = ["run", "--maze", "mazes/web.txt", "--algorithm", "self-adjusting-wall"]
    args += ["--profile", "web", "--noise", "realistic", "--json"]
    main([*args, "--seed", "5", "--record", str(tmp_path / "a.jsonl")])
    first = capsys.readouterr().out
    main([*args, "--seed", "5", "--record", str(tmp_path / "b.jsonl")])
    second = capsys.readouterr().out
    main([*args, "--seed", "6", "--record", str(tmp_path / "c.jsonl")])
    third = capsys.readouterr().out
    assert first == second
    assert json.loads(first)["seed"] == 5
    poses = [
        [line for line in (tmp_path / f"{n}.jsonl").read_text().splitlines()[1:-1]] for n in "abc"
    ]
    assert poses[0] == poses[1]
    assert poses[0] != poses[2] and first != third


def test_missing_sensor_is_a_setup_error_naming_the_mount():
    with pytest.raises(RunSetupError, match=r"needs a distance sensor mounted right.*--sensor"):
        result("erobotic", "right-wall", sensors=("distance:2:front",))


def test_a_maze_without_exits_runs_to_the_limit_and_succeeds(capsys):
    code = main(
        [
            "run",
            "--maze",
            "mazes/unity-default.txt",
            "--algorithm",
            "right-wall",
            "--max-time",
            "20",
        ]
    )
    assert code == 0
    assert "free exploration for 20 s" in capsys.readouterr().out
