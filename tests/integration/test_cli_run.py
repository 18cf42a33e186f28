"""`workbench run` and `workbench eval` as a user runs them: output, exit codes, bad input."""

import csv
import json
from pathlib import Path

import pytest

from workbench.cli import main
from workbench.sim.record import read_record


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
    # what ran: the maze, the profile and the driver
    assert data["maze"] == "eRobotic lab maze" and len(data["maze_digest"]) == 16
    assert data["profile"] == "erobotic" and data["driver"] == "algorithm right-wall"


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


@pytest.mark.parametrize(
    ("option", "said"),
    [
        (["--deadline", "0"], "--deadline must be above 0 and at most a day (seconds)"),
        (["--deadline", "100000"], "--deadline must be above 0 and at most a day (seconds)"),
        (["--memory", "10"], "--memory must be at least 256 (MiB)"),
    ],
)
def test_eval_refuses_limits_it_cannot_run_under(option, said, capsys):
    code = main(["eval", "--maze", "mazes/web.txt", "--algorithm", "right-wall", *option])
    assert code == 2
    assert capsys.readouterr().err == f"workbench eval: {said}\n"


def test_eval_stops_a_run_at_the_deadline_it_is_given(capsys):
    """right-wall never leaves the trap loop, and 100,000 simulated s take far longer than
    0.5 s: the run is stopped there, and the error names the run and the option."""
    code = main(["eval", "--maze", "mazes/trap-loop.txt", "--algorithm", "right-wall",
                 "--seeds", "1", "--max-time", "100000", "--deadline", "0.5",
                 "--jobs", "1"])  # fmt: skip
    assert code == 2
    err = capsys.readouterr().err
    assert "stopped after 0.5 s of wall-clock time, the limit for one run (--deadline)" in err


def test_eval_fits_80_columns_and_wide_keeps_one_line_per_entrant(tmp_path, capsys):
    # two programs of one name: each is named by its whole (long) path
    source = Path("programs/right-wall.viple").read_text(encoding="utf-8")
    paths = []
    for group in ("one", "two"):
        folder = tmp_path / f"submissions of the Tuesday afternoon group {group}" / "final"
        folder.mkdir(parents=True)
        (folder / "right-wall.viple").write_text(source, encoding="utf-8")
        paths.append(str(folder / "right-wall.viple"))
    args = ["eval", "--maze", "mazes/web.txt", "--profile", "web", "--seeds", "1", "--jobs", "2",
            "--algorithm", "right-wall", "two-distance-local-best",
            "--program", *paths]  # fmt: skip
    assert main(args) == 0
    lines = capsys.readouterr().out.splitlines()
    assert lines and all(len(line) <= 80 for line in lines), max(lines, key=len)
    assert lines[1].split() == ["#", "entrant", "out", "turn", "deg", "blocks", "time", "s",
                                "hits", "touches"]  # fmt: skip
    text = "\n".join(lines)
    assert "two-distance-local-best" in text
    # a name too long for its column stands whole above its figures
    names, name = [], ""
    for line in lines[2:]:
        if line.strip().startswith("1/1"):
            names.append(name)
        elif line[2:3].isdigit():
            name = line[4:]
        else:
            name += line[4:]
    assert sorted(names) == sorted(paths)
    assert main([*args, "--wide"]) == 0
    wide = capsys.readouterr().out.splitlines()
    assert any(line.split()[-2:] == ["collisions", "touches"] for line in wide)
    assert sum(path in line for line in wide for path in paths) == 2


def test_a_bundled_maze_is_found_by_its_name(tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)  # nothing named web here: the bundled maze is meant
    assert main(["run", "--maze", "web", "--algorithm", "web-wall-following", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["reached_exit"] and out["distance_cells"] > 50  # the Web Simulator's maze
    (tmp_path / "web").write_text("not a maze")  # a file of that name is what is meant
    assert main(["run", "--maze", "web", "--algorithm", "right-wall"]) == 2
    assert "web" in capsys.readouterr().err


#: an algorithm whose guard divides by zero at its first control tick after the start
FAILING_GUARD = """\
name: divider
description: a guard that divides by the difference of a reading with itself
sensors:
  front: {kind: distance, mount: front, port: 1}
initial: go
states:
  go:
    on_enter:
      - move: 1
    transitions:
      - when: "1 / (front - front) > 0"
        to: go
"""


def test_a_guard_failing_mid_run_is_a_clear_error_and_the_record_reads_as_cut_off(tmp_path, capsys):
    algorithm = tmp_path / "divider.yaml"
    algorithm.write_text(FAILING_GUARD)
    record = tmp_path / "run.jsonl"
    assert main(["run", "--maze", "mazes/web.txt", "--algorithm", str(algorithm),
                 "--record", str(record)]) == 2  # fmt: skip
    err = capsys.readouterr().err
    assert err.startswith("workbench run: the run failed after 0.10 s: divider, state go: guard")
    assert "division by zero" in err and "Traceback" not in err
    cut = read_record(record)
    assert cut.summary is None and cut.ticks[0]["state"] == "go"
    # in a matrix the failing entrant is named with its maze and seed, and nothing is ranked
    args = ["eval", "--maze", "mazes/web.txt", "--algorithm", "right-wall", str(algorithm),
            "--seeds", "1", "--jobs", "2"]  # fmt: skip
    assert main(args) == 2
    out, err = capsys.readouterr()
    assert out == ""
    assert err.startswith(f"workbench eval: {algorithm} on mazes/web.txt, seed 0: the run failed")
