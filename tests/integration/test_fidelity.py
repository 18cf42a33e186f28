"""The simulator teaches the course's lessons, not artefacts of its geometry (measured over
seeds; `bench/fidelity.py` gives the full figures)."""

import json

import pytest

from workbench.cli import main
from workbench.control.evaluate import evaluate, format_table
from workbench.control.headless import AlgorithmPilot, RunSpec, run
from workbench.fsm.algorithms import load_algorithm
from workbench.fsm.machine import FsmController, bind_sensors, preset_sensors
from workbench.sim.driver import Driver
from workbench.sim.generate import generate
from workbench.sim.session import Session


def follow_right_wall(maze, profile, seed, max_time=1500.0, noise=None):
    definition = load_algorithm("right-wall")
    sensors = preset_sensors(definition, profile)
    session = Session(maze, profile, sensors, noise, seed=seed)
    session.attach(
        FsmController(definition, None, profile),
        bind_sensors(definition, sensors, profile),
        Driver.algorithm("right-wall"),
    )
    return session.run(max_time)


@pytest.mark.parametrize("hand", ["right", "left"])
def test_wall_followers_get_out_of_every_generated_braid_maze(hand):
    for seed in range(5):
        maze = generate(8, 8, seed, "braid")
        # a left-hand rule on a maze is the right-hand rule on its mirror image
        metrics = follow_right_wall(maze if hand == "right" else maze.mirrored(), "unity", seed)
        assert metrics.reached_exit, f"seed {seed}: {hand} wall following did not get out"


#: (hand, seed) of 16 x 16 mazes where the low level's old motor imbalance (0.02 %) and turn
#: error (0.1 %) made the plain follower take false openings (2.1 and 2.6 times the turning)
LONG_RUNS = [("right", 3), ("left", 2)]


@pytest.mark.parametrize(("hand", "seed"), LONG_RUNS)
def test_plain_wall_following_keeps_its_margin_on_long_unity_runs_at_the_default_noise(hand, seed):
    maze = generate(16, 16, seed)
    maze = maze if hand == "right" else maze.mirrored()
    exact = follow_right_wall(maze, "unity", seed, 4000.0, noise="off")
    noisy = follow_right_wall(maze, "unity", seed, 4000.0)  # the profile's default: low
    assert exact.reached_exit and noisy.reached_exit
    # a false opening costs a right turn into the wall and a left turn back out: 180 degrees
    assert noisy.turn_degrees == pytest.approx(exact.turn_degrees, rel=0.01)
    assert noisy.collisions == 0
    assert noisy.sim_time < 1.01 * exact.sim_time


RANKED = {
    "rank-local-best-wins": (
        "two-distance-local-best",
        ["right-wall", "farthest-distance", "one-distance-first", "first-working-solution"],
    ),
    "rank-wall-wins": (
        "right-wall",
        ["farthest-distance", "one-distance-first", "two-distance-local-best"],
    ),
}


@pytest.mark.parametrize("maze", sorted(RANKED))
def test_ranking_mazes_show_their_winner_under_their_own_profiles_default_noise(maze):
    winner, others = RANKED[maze]
    for seed in range(10):
        mine = run(RunSpec(f"mazes/{maze}.txt", AlgorithmPilot(winner), seed=seed)).as_dict()
        assert mine["reached_exit"], seed
        for other in others:
            theirs = run(RunSpec(f"mazes/{maze}.txt", AlgorithmPilot(other), seed=seed)).as_dict()
            if theirs["reached_exit"]:
                assert mine["distance_cells"] < theirs["distance_cells"], (seed, other)
                assert mine["turn_degrees"] < theirs["turn_degrees"], (seed, other)


def test_web_wall_following_touches_walls_on_purpose_without_colliding(capsys):
    argv = ["run", "--maze", "mazes/web.txt", "--algorithm", "web-wall-following"]
    assert main([*argv, "--profile", "web", "--noise", "off", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["reached_exit"] and out["collisions"] == 0 and out["touches"] >= 5
    assert main([*argv, "--profile", "web", "--noise", "off"]) == 0
    assert f"touches             {out['touches']} " in capsys.readouterr().out


def test_eval_tables_carry_touches_beside_collisions():
    result = evaluate(["mazes/web.txt"], ["web-wall-following"], seeds=1, profile="web", jobs=1)
    cell = result.cell("mazes/web.txt", "web-wall-following")
    assert cell.mean["collisions"] == 0 and cell.mean["touches"] >= 5
    header = format_table(result).splitlines()[1]
    assert header.split()[-2:] == ["collisions", "touches"]
