"""``workbench picture`` and ``--picture`` on run, eval and viple run: good records drawn,
bad input refused with the file and the fix, exit code 2, no traceback, no file left."""

from __future__ import annotations

import json
import os
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest

from tests.pictures.records import BEND, LOOP, lines, maze_file, record_of, write_lines
from tests.pictures.svg import path_points, texts
from workbench.cli import main
from workbench.pictures.runs import MAX_RECORD

PROGRAMS = Path(__file__).resolve().parents[2] / "programs"


def _picture(capsys, *argv: str) -> tuple[int, str, str]:
    code = main(["picture", *argv])
    out, err = capsys.readouterr()
    return code, out, err


def _refused(capsys, tmp_path, *argv: str) -> str:
    target = tmp_path / "out.svg"
    code, out, err = _picture(capsys, *argv, "-o", str(target))
    assert code == 2
    assert "Traceback" not in err and out == ""
    assert not target.exists()
    assert os.listdir(tmp_path).count("out.svg") == 0
    return err


def test_one_record_and_several(tmp_path, capsys):
    a = record_of(tmp_path, text=LOOP, name="loop.txt")
    b = record_of(tmp_path, "farthest-distance", text=LOOP, name="loop.txt")
    code, out, _ = _picture(capsys, str(a), "-o", str(tmp_path / "a.svg"), "--at", "1")
    assert code == 0 and "picture (path)" in out and "a.svg" in out
    code, out, _ = _picture(capsys, str(a), str(b), "-o", str(tmp_path / "ab.png"))
    assert code == 0 and "picture (compare)" in out
    assert (tmp_path / "ab.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    code, out, _ = _picture(capsys, str(a), "--kind", "time", "-o", str(tmp_path / "t.svg"))
    assert code == 0 and "sensor" in (tmp_path / "t.svg").read_text()


def test_a_damaged_record(tmp_path, capsys):
    record = record_of(tmp_path)
    text = record.read_text().splitlines(keepends=True)
    text[4] = '{"t": 0.25, "pose": [1, 2\n'
    damaged = tmp_path / "damaged.jsonl"
    damaged.write_text("".join(text))
    err = _refused(capsys, tmp_path, str(damaged))
    assert "damaged.jsonl:5: not JSON" in err and "draw another record" in err


def test_a_record_cut_off_mid_line(tmp_path, capsys):
    record = record_of(tmp_path)
    data = record.read_bytes()
    cut = tmp_path / "cut.jsonl"
    cut.write_bytes(data[: len(data) // 2])
    err = _refused(capsys, tmp_path, str(cut))
    assert "cut.jsonl:" in err and "not JSON" in err


def test_a_record_without_its_summary_is_drawn_as_cut_off(tmp_path, capsys):
    record = record_of(tmp_path)
    objects = lines(record)
    crashed = write_lines(tmp_path / "crashed.jsonl", objects[: len(objects) // 2])
    target = tmp_path / "crashed.svg"
    code, _, _ = _picture(capsys, str(crashed), "-o", str(target))
    assert code == 0
    assert "the record was cut off (no summary line)" in texts(target.read_bytes())


def test_a_huge_file_is_refused_unread(tmp_path, capsys):
    huge = tmp_path / "huge.jsonl"
    with open(huge, "wb") as fh:
        fh.truncate(MAX_RECORD + 1)
    err = _refused(capsys, tmp_path, str(huge))
    assert "huge.jsonl" in err and "larger than any run record" in err


def test_not_a_plain_file(tmp_path, capsys):
    err = _refused(capsys, tmp_path, "/dev/zero")
    assert "/dev/zero: not a plain file" in err
    err = _refused(capsys, tmp_path, str(tmp_path / "missing.jsonl"))
    assert "missing.jsonl: no such file" in err


def test_a_header_with_an_escape_is_refused(tmp_path, capsys):
    objects = lines(record_of(tmp_path))
    objects[0]["maze"]["name"] = "Bend\x1b[2J"
    hostile = write_lines(tmp_path / "hostile.jsonl", objects)
    err = _refused(capsys, tmp_path, str(hostile))
    assert "hostile.jsonl:1" in err and "\x1b" not in err


def test_hostile_state_names_are_drawn_as_text(tmp_path, capsys):
    objects = lines(record_of(tmp_path))
    for obj in objects[1:-1]:
        obj["state"] = "$\\frac{1}{0}$ <b>&\x1b[31m" + "x" * 500
    hostile = write_lines(tmp_path / "states.jsonl", objects)
    target = tmp_path / "states.svg"
    code, _, err = _picture(capsys, str(hostile), "--kind", "time", "-o", str(target))
    assert code == 0, err
    svg = target.read_bytes()
    ET.fromstring(svg)  # still well-formed XML
    assert b"\x1b" not in svg
    assert "$\\frac{1}{0}$ <b>&\\x1b[31mxxx" in texts(svg)


def test_poses_outside_the_maze(tmp_path, capsys):
    objects = lines(record_of(tmp_path))
    objects[3]["pose"] = [1e300, 5.0, 0.0]
    far = write_lines(tmp_path / "far.jsonl", objects)
    err = _refused(capsys, tmp_path, str(far))
    assert "far.jsonl: tick 3 puts the robot at" in err and "outside the maze Bend" in err


def test_a_record_of_another_maze_than_the_one_given(tmp_path, capsys):
    record = record_of(tmp_path)
    err = _refused(capsys, tmp_path, str(record), "--maze", "web")
    assert "a run on Bend, not on Web Simulator lab maze" in err
    # the right one is drawn
    maze = maze_file(tmp_path, BEND, "bend.txt")
    code, _, _ = _picture(capsys, str(record), "--maze", str(maze), "-o", str(tmp_path / "b.svg"))
    assert code == 0


def test_runs_of_different_mazes_side_by_side(tmp_path, capsys):
    a = record_of(tmp_path)
    b = record_of(tmp_path, text=LOOP, name="loop.txt")
    err = _refused(capsys, tmp_path, str(a), str(b))
    assert "must share one maze" in err and "Loop" in err and "Bend" in err


def test_a_maze_file_that_is_gone(tmp_path, capsys):
    record = record_of(tmp_path)
    (tmp_path / "bend.txt").unlink()
    moved = tmp_path / "elsewhere"
    moved.mkdir()
    record = record.rename(moved / record.name)
    err = _refused(capsys, tmp_path, str(record))
    assert "give the run's maze file with --maze FILE" in err


def test_an_output_that_cannot_be_written(tmp_path, capsys):
    record = record_of(tmp_path)
    for target, words in (
        (tmp_path / "no" / "a.svg", "its folder does not exist"),
        (tmp_path / "a.pdf", "a picture is saved as .svg or .png"),
    ):
        code, _, err = _picture(capsys, str(record), "-o", str(target))
        assert code == 2 and words in err and str(target) in err and "Traceback" not in err
        assert not target.exists()
    (tmp_path / "dir.svg").mkdir()
    code, _, err = _picture(capsys, str(record), "-o", str(tmp_path / "dir.svg"))
    assert code == 2 and "a folder, not a file" in err


def test_a_size_out_of_range(tmp_path, capsys):
    record = record_of(tmp_path)
    for size, words in (("10x10", "from 200 to 4000"), ("big", "WIDTHxHEIGHT")):
        err = _refused(capsys, tmp_path, str(record), "--size", size)
        assert words in err


def test_run_draws_its_picture(tmp_path, capsys):
    maze = maze_file(tmp_path)
    target = tmp_path / "run.svg"
    code = main(["run", "--maze", str(maze), "--algorithm", "right-wall", "--json",
                 "--profile", "erobotic", "--picture", str(target)])  # fmt: skip
    out, err = capsys.readouterr()
    assert code == 0
    assert json.loads(out)["reached_exit"] is True  # stdout stays one JSON object
    assert "picture (path)" in err
    assert path_points(target.read_bytes(), "robot-path") > 10
    assert "run not kept (--record keeps it)" in texts(target.read_bytes())
    assert os.listdir(tmp_path) == sorted(["bend.txt", "run.svg"]) or set(os.listdir(tmp_path)) == {
        "bend.txt",
        "run.svg",
    }


def test_run_on_a_micromouse_maze_draws_its_picture(tmp_path, capsys, monkeypatch):
    """A micromouse maze, named by a path relative to the folder the command runs in, is
    read again from its file to draw the run (its source says it was turned into blocks)."""
    (tmp_path / "mazes").mkdir()
    (tmp_path / "mazes" / "mouse.txt").write_text(
        "o---o---o---o\n| G         |\no   o---o   o\n| S |       |\no---o---o---o\n"
    )
    monkeypatch.chdir(tmp_path)
    code = main(["run", "--maze", "mazes/mouse.txt", "--algorithm", "right-wall",
                 "--profile", "erobotic", "--picture", "mouse.svg"])  # fmt: skip
    _, err = capsys.readouterr()
    assert code == 0, err
    assert "picture (path)" in err and "not found" not in err
    assert path_points((tmp_path / "mouse.svg").read_bytes(), "robot-path") > 10


def test_run_refuses_a_picture_it_could_not_write_before_it_runs(tmp_path, capsys):
    maze = maze_file(tmp_path)
    record = tmp_path / "r.jsonl"
    code = main(["run", "--maze", str(maze), "--algorithm", "right-wall", "--record",
                 str(record), "--picture", str(tmp_path / "no" / "p.svg")])  # fmt: skip
    _, err = capsys.readouterr()
    assert code == 2 and "--picture" in err and "its folder does not exist" in err
    assert not record.exists()


def test_viple_run_draws_its_picture(tmp_path, capsys):
    target = tmp_path / "program.png"
    code = main(["viple", "run", str(PROGRAMS / "right-wall.viple"), "--maze", "web",
                 "--picture", str(target)])  # fmt: skip
    _, err = capsys.readouterr()
    assert code == 0 and "picture (path)" in err
    assert target.read_bytes()[:4] == b"\x89PNG"


@pytest.mark.parametrize("mazes", [["one"], ["one", "two"]])
def test_eval_draws_one_picture_per_maze(tmp_path, capsys, mazes):
    paths = [str(maze_file(tmp_path, BEND if m == "one" else LOOP, f"{m}.txt")) for m in mazes]
    target = tmp_path / "report.svg"
    code = main(["eval", "--maze", *paths, "--algorithm", "right-wall", "farthest-distance",
                 "--seeds", "1", "--jobs", "1", "--profile", "erobotic",
                 "--picture", str(target)])  # fmt: skip
    _, err = capsys.readouterr()
    assert code == 0, err
    names = ["report.svg"] if len(mazes) == 1 else ["report-one.svg", "report-two.svg"]
    for name in names:
        svg = (tmp_path / name).read_bytes()
        assert path_points(svg, "robot-path-1") > 2 and path_points(svg, "robot-path-2") > 2
        assert "2 runs side by side" in texts(svg)


def test_grade_draws_each_mazes_programs_side_by_side(tmp_path, capsys):
    folder = tmp_path / "handins"
    for student in ("ana", "ben"):
        (folder / student).mkdir(parents=True)
        (folder / student / "wall.viple").write_bytes((PROGRAMS / "right-wall.viple").read_bytes())
    (folder / "cat").mkdir()
    (folder / "cat" / "broken.viple").write_text("not a program\n")
    target = tmp_path / "grade.svg"
    code = main(["grade", str(folder), "--maze", "web", "web", "--jobs", "1",
                 "--out", str(tmp_path / "table.csv"), "--picture", str(target)])  # fmt: skip
    _, err = capsys.readouterr()
    assert code == 0, err
    for name in ("grade-web.svg", "grade-web-2.svg"):  # (the same maze twice: numbered)
        svg = (tmp_path / name).read_bytes()
        words = texts(svg)
        assert "2 runs side by side" in words  # cat's program did not load: no run to draw
        assert "001-ana.jsonl" in words and "002-ben.jsonl" in words
        assert path_points(svg, "robot-path-1") > 2
    assert "picture (compare)" in err


def test_grade_refuses_a_picture_it_could_not_write(tmp_path, capsys):
    folder = tmp_path / "handins"
    folder.mkdir()
    (folder / "ana.viple").write_bytes((PROGRAMS / "right-wall.viple").read_bytes())
    code = main(["grade", str(folder), "--maze", "web", "--picture", str(tmp_path / "g.pdf")])
    _, err = capsys.readouterr()
    assert code == 2 and "--picture" in err and "g.pdf" in err and ".svg or .png" in err


def test_run_draws_a_long_run_whose_record_reached_the_cap(tmp_path, capsys, monkeypatch):
    """A command's record stops at the cap every record the workbench writes keeps, so a run
    too long for it is still drawn (the cap is made small here; a real one is 20 MB, which a
    run of some hours reaches)."""
    monkeypatch.setattr("workbench.control.lifecycle.RECORD_CAP", 60_000)
    maze = tmp_path / "loop.txt"
    maze.write_text("#######\n#.....#\n#.###.#\n#S....#\n#######\n")  # no exit: it goes round
    target = tmp_path / "long.svg"
    record = tmp_path / "long.jsonl"
    code = main(["run", "--maze", str(maze), "--algorithm", "right-wall", "--profile",
                 "erobotic", "--max-time", "600", "--record", str(record),
                 "--picture", str(target)])  # fmt: skip
    out, err = capsys.readouterr()
    assert code == 0, err
    assert "run record          stopped after" in out and "60,000" in out
    assert record.stat().st_size <= 60_000
    assert "picture (path)" in err
    assert path_points(target.read_bytes(), "robot-path") > 10
    # the caption says where the drawn path ends, since the figures are the whole run's
    stopped = float(out.split("run record          stopped after ")[1].split(" s")[0])
    said = (
        f"the record stopped at {stopped:.1f} s (its size limit): the path and its marks end there"
    )
    assert said in texts(target.read_bytes())
    over_time = tmp_path / "long-time.svg"
    code, _, err = _picture(capsys, str(record), "--kind", "time", "-o", str(over_time))
    assert code == 0, err
    assert said in texts(over_time.read_bytes())
    side_by_side = tmp_path / "long-compare.svg"
    code, _, err = _picture(capsys, str(record), str(record), "-o", str(side_by_side))
    assert code == 0, err
    assert f"not out | path ends at {stopped:.1f} s (record stopped)" in texts(
        side_by_side.read_bytes()
    )
