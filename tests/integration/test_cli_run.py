"""`workbench run` and `workbench eval` as a user runs them: output, exit codes, bad input."""

import csv
import json

import pytest

from workbench.cli import main


def test_run_prints_a_readable_summary_and_exits_0_when_out(capsys):
    code = main(["run", "--maze", "mazes/erobotic.txt", "--algorithm", "farthest-distance"])
    out = capsys.readouterr().out
    assert code == 0
    assert "reached the exit after" in out
    assert "turning degrees" in out and "distance travelled" in out and "px" in out


def test_run_json_has_the_documented_keys(capsys):
    code = main(["run", "--maze", "mazes/erobotic.txt", "--algorithm", "right-wall", "--json"])
    data = json.loads(capsys.readouterr().out)
    assert code == 0
    assert list(data)[:11] == [
        "reached_exit",
        "sim_time",
        "distance",
        "distance_cells",
        "turn_degrees",
        "turns",
        "collisions",
        "touches",
        "efficiency",
        "final_state",
        "seed",
    ]
    assert 0 < data["efficiency"] <= 1


def test_run_cut_by_the_time_limit_exits_1_and_says_so(capsys):
    code = main(
        ["run", "--maze", "mazes/trap-loop.txt", "--algorithm", "right-wall",
         "--profile", "erobotic", "--max-time", "60"]
    )  # fmt: skip
    assert code == 1
    assert "did NOT get out within the 60 s limit (the run was cut" in capsys.readouterr().out


@pytest.mark.parametrize(
    ("extra", "message"),
    [
        (["--algorithm", "wall-right"], "no built-in algorithm or FSM file named 'wall-right'"),
        (["--algorithm", "right-wall", "--sensor", "distance:x:right"], "is not a whole number"),
        (["--algorithm", "right-wall", "--sensor", "sonar:1:right"], "unknown sensor kind"),
        (
            [
                "--algorithm",
                "right-wall",
                "--sensor",
                "distance:1:right",
                "--sensor",
                "touch:1:front",
            ],
            "port 1 is used twice",
        ),
        (["--algorithm", "right-wall", "--param", "open_right=wide"], "'wide' is not a number"),
        (["--algorithm", "right-wall", "--noise-set", "turn_error"], "must be NAME=VALUE"),
    ],
)
def test_run_bad_input_exits_2_with_a_clear_message(capsys, extra, message):
    code = main(["run", "--maze", "mazes/erobotic.txt", *extra])
    assert code == 2
    assert message in capsys.readouterr().err


def test_run_invalid_maze_exits_2_with_positions(tmp_path, capsys):
    maze = tmp_path / "open.txt"
    maze.write_text("#####\n#S..E\n#...#\n##.##\n")
    code = main(["run", "--maze", str(maze), "--algorithm", "right-wall"])
    assert code == 2
    assert f"{maze}:4:3: open floor on the outer boundary" in capsys.readouterr().err


def test_run_record_file_is_written(tmp_path, capsys):
    record = tmp_path / "run.jsonl"
    main(["run", "--maze", "mazes/erobotic.txt", "--algorithm", "right-wall",
          "--record", str(record)])  # fmt: skip
    lines = record.read_text().splitlines()
    assert json.loads(lines[0])["algorithm"] == "right-wall"
    assert json.loads(lines[-1])["type"] == "summary"
    assert record.stat().st_size < 200_000


def test_run_record_to_an_unwritable_place_exits_2(tmp_path, capsys):
    code = main(["run", "--maze", "mazes/erobotic.txt", "--algorithm", "right-wall",
                 "--record", str(tmp_path / "no" / "such" / "dir.jsonl")])  # fmt: skip
    assert code == 2
    assert "cannot write the record" in capsys.readouterr().err


def test_eval_ranks_and_writes_csv_and_json(tmp_path, capsys):
    out_csv = tmp_path / "m.csv"
    args = ["eval", "--maze", "mazes/erobotic.txt", "--algorithm", "right-wall",
            "farthest-distance", "--seeds", "2", "--jobs", "2", "--csv", str(out_csv)]  # fmt: skip
    assert main(args) == 0
    table = capsys.readouterr().out
    assert table.index("farthest-distance") < table.index("right-wall")
    rows = list(csv.DictReader(out_csv.open()))
    assert [r["algorithm"] for r in rows] == ["farthest-distance", "right-wall"]
    assert rows[0]["rank"] == "1" and rows[0]["runs"] == "2"
    assert main([*args, "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["ranking"]["mazes/erobotic.txt"] == ["farthest-distance", "right-wall"]


def test_eval_json_is_identical_for_any_number_of_jobs(capsys):
    args = ["eval", "--maze", "mazes/web.txt", "--algorithm", "right-wall", "--seeds", "2",
            "--noise", "realistic", "--profile", "web", "--json"]  # fmt: skip
    main([*args, "--jobs", "1"])
    one = capsys.readouterr().out
    main([*args, "--jobs", "2"])
    assert capsys.readouterr().out == one


def test_eval_bad_algorithm_exits_2(capsys):
    code = main(["eval", "--maze", "mazes/web.txt", "--algorithm", "nope", "--jobs", "1"])
    assert code == 2
    assert "nope on mazes/web.txt" in capsys.readouterr().err
