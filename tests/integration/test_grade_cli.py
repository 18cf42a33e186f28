"""`workbench grade` on a class's folder, and `workbench eval --keys`, as an instructor runs
them."""

from __future__ import annotations

import csv
import io
import json
import os
import re
import sys
from pathlib import Path

from tests.program.graded_programs import memory_hog, right_wall, runaway
from workbench.cli import main

ROOT = Path(__file__).resolve().parents[2]
WEB = str(ROOT / "mazes" / "web.txt")
RANK = str(ROOT / "mazes" / "rank-wall-wins.txt")


def class_folder(tmp_path: Path) -> Path:
    """A class's hand-ins: a good program, one that waits for a key (and brings its key
    script), a broken file, a file that is no VIPLE program, one that never ends, one that
    allocates without end, and a stray note."""
    folder = tmp_path / "handins"
    folder.mkdir()
    right_wall(folder / "ana.viple")
    (folder / "ben").mkdir()
    right_wall(folder / "ben" / "follower.viple", start_key="a")
    (folder / "ben" / "follower.keys").write_text("a@0.5\n")
    good = (folder / "ana.viple").read_bytes()
    (folder / "cy.viple").write_bytes(good[: len(good) // 2])
    (folder / "di.viple").write_text("states:\n  forward: {move: 0.5}\n")
    runaway(folder / "ed.viple")
    memory_hog(folder / "flo.viple")
    (folder / "notes.txt").write_text("ed said he would hand in later")
    return folder


def test_a_class_folder_grades_into_one_table_whatever_the_jobs(tmp_path, capsys):
    folder = class_folder(tmp_path)
    args = ["grade", str(folder), "--maze", WEB, RANK, "--profile", "web", "--max-time", "36000"]
    args += ["--deadline", "8", "--memory", "400"]
    tables = []
    for jobs in ("1", "2"):
        out_csv, out_json = tmp_path / f"t{jobs}.csv", tmp_path / f"t{jobs}.json"
        code = main([*args, "--jobs", jobs, "--out", str(out_csv), "--out", str(out_json)])
        assert code == 0
        captured = capsys.readouterr()
        assert captured.out == ""  # the table went to the files
        assert captured.err.startswith("6 programs, 12 runs: 4 load, 2 reached the exit")
        tables.append((out_csv.read_bytes(), out_json.read_bytes()))
    assert tables[0] == tables[1]

    rows = list(csv.DictReader(tables[0][0].decode().splitlines()))
    assert [(r["student"], r["maze"]) for r in rows] == [
        (name, maze)
        for name in ("ana", "ben", "cy", "di", "ed", "flo")
        for maze in ("web.txt", "rank-wall-wins.txt")
    ]
    by = {(r["student"], r["maze"]): r for r in rows}
    for name in ("ana", "ben"):  # ben's program moves once its key script presses a
        for maze in ("web.txt", "rank-wall-wins.txt"):
            row = by[name, maze]
            assert (row["loads"], row["reached_exit"], row["refusal"]) == ("yes", "yes", "")
            assert float(row["distance_blocks"]) > 5 and float(row["time"]) < 200
    assert by["ben", "web.txt"]["file"] == "ben/follower.viple"
    assert by["cy", "web.txt"]["loads"] == "no"
    assert by["cy", "web.txt"]["refusal"].startswith("cy.viple: line ")
    di = by["di", "web.txt"]
    assert di["loads"] == "no" and "not well formed" in di["refusal"]
    ed = by["ed", "web.txt"]
    assert ed["loads"] == "yes" and ed["reached_exit"] == "no"
    # the interpreter's own bounds stop both at once, deterministically (the process-level
    # deadline and memory cap behind them are tested in tests/program/test_grading.py)
    assert ed["refusal"].startswith("stopped at 1.00 s: panel Main: activity")
    assert "a loop that never waits?" in ed["refusal"] and ed["time"] == "1.0"
    flo = by["flo", "web.txt"]
    assert flo["loads"] == "yes" and flo["reached_exit"] == "no"
    assert flo["refusal"].startswith("stopped at ") and "(Join)" in flo["refusal"]
    data = json.loads(tables[0][1])
    assert data["mazes"] == ["web.txt", "rank-wall-wins.txt"] and data["max_time"] == 36000
    assert data["rows"][0]["program_sha256"] == by["ana", "web.txt"]["program_sha256"]


def test_an_exercise_gives_the_mazes_profile_and_sensors(tmp_path, capsys):
    folder = tmp_path / "handins"
    folder.mkdir()
    right_wall(folder / "ana.viple")
    args = ["grade", str(folder), "--lab", "web-simulator", "--exercise", "wall-main"]
    assert main(args) == 0
    rows = list(csv.DictReader(capsys.readouterr().out.splitlines()))
    assert [(r["maze"], r["reached_exit"]) for r in rows] == [("web.txt", "yes")]
    # the Unity exercise's robot has a distance sensor where this program reads a touch sensor
    args = ["grade", str(folder), "--lab", "unity-simulator", "--exercise", "wall-following"]
    assert main(args) == 0
    rows = list(csv.DictReader(capsys.readouterr().out.splitlines()))
    assert [r["maze"] for r in rows] == ["erobotic.txt", "rank-wall-wins.txt",
                                         "rank-local-best-wins.txt"]  # fmt: skip
    assert all(r["loads"] == "yes" and "it reads port 2" in r["refusal"] for r in rows)


def test_grade_refuses_what_it_cannot_use(tmp_path, capsys):
    folder = tmp_path / "handins"
    folder.mkdir()
    lab = ["--lab", "web-simulator", "--exercise", "wall-main"]
    cases = [
        (["--maze", WEB, *lab], "--maze is the exercise's"),
        (["--lab", "web-simulator"], "give --lab L and --exercise E together"),
        (["--lab", "nosuch", "--exercise", "x"], "--lab nosuch: no such lab"),
        (["--lab", "web-simulator", "--exercise", "x"], "has no exercise 'x'"),
        ([], "give --lab L --exercise E, or the mazes"),
        (["--maze", WEB, "--keys", "a"], "key 1 'a' must be KEY@SECONDS"),
        (["--maze", WEB, "--out", "t.xlsx"], "name a .csv or a .json file"),
        (["--maze", WEB, "--memory", "10"], "--memory must be at least"),
        (["--maze", WEB], "holds no programs"),
    ]  # fmt: skip
    for extra, message in cases:
        assert main(["grade", str(folder), *extra]) == 2
        assert message in capsys.readouterr().err
    assert main(["grade", str(tmp_path / "gone"), "--maze", WEB]) == 2
    assert "no such folder" in capsys.readouterr().err


def test_a_viple_3_xml_hand_in_is_graded_and_every_file_passed_over_is_named(tmp_path, capsys):
    folder = tmp_path / "handins"
    folder.mkdir()
    right_wall(folder / "ana.xml", viple3=True)  # as VIPLE 3.1 saves: gzip-compressed XML
    right_wall(folder / "ben.viple")
    (folder / "notes.txt").write_text("ed said he would hand in later")
    os.mkfifo(folder / "ed.viple")  # never opened: reading it would block the grading
    table = tmp_path / "t.json"
    args = ["grade", str(folder), "--maze", WEB, "--profile", "web", "--max-time", "400"]
    assert main([*args, "--out", str(table)]) == 0
    err = capsys.readouterr().err
    assert err.startswith("2 programs, 2 runs: 2 load, 2 reached the exit on every run")
    assert "skipped 2 files of the folder:\n" in err
    assert "  ed.viple: a named pipe (FIFO), not a plain file: never opened" in err
    assert "  notes.txt: not a VIPLE program (the app runs .viple or .xml files)" in err
    data = json.loads(table.read_text())
    assert [(r["student"], r["file"], r["reached_exit"]) for r in data["rows"]] == [
        ("ana", "ana.xml", True),
        ("ben", "ben.viple", True),
    ]
    assert [s["file"] for s in data["skipped"]] == ["ed.viple", "notes.txt"]
    assert all(s["reason"] for s in data["skipped"])
    # a folder with nothing to grade says what it passed over
    (folder / "ana.xml").unlink()
    (folder / "ben.viple").unlink()
    assert main(args) == 2
    err = capsys.readouterr().err
    assert "holds no programs (NAME.viple or .xml files" in err
    assert "ed.viple: a named pipe (FIFO)" in err and "notes.txt: not a VIPLE program" in err


def test_eval_presses_a_key_script_for_a_program_that_waits_for_one(tmp_path, capsys):
    program = right_wall(tmp_path / "follower.viple", start_key="a")
    args = ["eval", "--maze", WEB, "--program", program, "--profile", "web", "--seeds", "1"]
    args += ["--jobs", "1", "--max-time", "200", "--json"]

    def reached(*extra: str) -> int:
        assert main([*args, *extra]) == 0
        return json.loads(capsys.readouterr().out)["cells"][0]["reached"]

    assert reached() == 0
    assert reached("--keys", "a@0.5") == 1
    script = tmp_path / "start.txt"
    script.write_text("a@0.5\n")
    assert reached("--keys-file", str(script)) == 1
    (tmp_path / "follower.keys").write_text("a@1")  # the program's own script comes first
    assert reached("--keys", "w@0.5") == 1
    (tmp_path / "follower.keys").write_text("a at 1")
    assert main(args) == 2
    assert "follower.keys: key 1 'a'" in capsys.readouterr().err


class _Terminal(io.StringIO):
    def isatty(self) -> bool:
        return True


def test_progress_on_a_terminal_names_each_program_then_the_summary(tmp_path, monkeypatch):
    folder = tmp_path / "handins"
    folder.mkdir()
    right_wall(folder / "ana.viple")
    (folder / "bo.viple").write_text("not a program")
    terminal = _Terminal()
    monkeypatch.setattr(sys, "stderr", terminal)
    out = tmp_path / "t.csv"
    assert main(["grade", str(folder), "--maze", WEB, "--profile", "web", "--out", str(out)]) == 0
    shown = terminal.getvalue()
    lines = sorted(re.findall(r"graded (\d) of 2: (\w+\.viple)", shown))
    assert [n for n, _ in lines] == ["1", "2"]
    assert sorted(name for _, name in lines) == ["ana.viple", "bo.viple"]
    last = shown.rsplit("\r\x1b[K", 1)[1]  # the progress line is cleared before the summary
    assert last.startswith("2 programs, 2 runs: 1 load, 1 reached the exit on every run")
