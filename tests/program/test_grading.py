"""Grading a folder of programs: what a folder holds, the outer wall around each program's
process, and the table."""

from __future__ import annotations

import csv
import io
import json
import os
from pathlib import Path

import pytest

from tests.program import hostile
from tests.program.graded_programs import right_wall
from tests.program.hostile_pilots import HostilePilot
from workbench.program.grade_table import COLUMNS, csv_text, json_text, summary
from workbench.program.grading import Limits, Plan, Row, grade
from workbench.program.submissions import (
    FolderError,
    Skipped,
    find_submissions,
    scan_folder,
    shown_name,
)

MAZES = Path(__file__).resolve().parents[2] / "mazes"
WEB = str(MAZES / "web.txt")
RANK = str(MAZES / "rank-wall-wins.txt")


def test_a_folder_holds_files_and_subfolders_one_student_each(tmp_path):
    right_wall(tmp_path / "zoe.VIPLE")
    (tmp_path / "amy").mkdir()
    right_wall(tmp_path / "amy" / "walls.viple", start_key="a")
    (tmp_path / "amy" / "walls.keys").write_text("a@0.5\nrelease@40\n")
    (tmp_path / "amy" / "notes.txt").write_text("my notes")
    (tmp_path / "two").mkdir()
    right_wall(tmp_path / "two" / "a.viple")
    right_wall(tmp_path / "two" / "b.viple")
    (tmp_path / "empty").mkdir()
    (tmp_path / "badkeys.viple").write_bytes((tmp_path / "zoe.VIPLE").read_bytes())
    (tmp_path / "badkeys.keys").write_text("w at 3")
    (tmp_path / "link.viple").symlink_to(tmp_path / "zoe.VIPLE")
    (tmp_path / ".hidden.viple").write_text("<Program/>")
    (tmp_path / "readme.txt").write_text("not a program")

    found = find_submissions(tmp_path, keys="d@1")
    assert [s.student for s in found] == ["amy", "badkeys", "empty", "link", "two", "zoe"]
    amy, badkeys, empty, link, two, zoe = found
    assert (amy.file, amy.keys, amy.refused) == ("amy/walls.viple", "a@0.5 release@40", "")
    assert len(amy.sha256) == 64
    assert zoe.keys == "d@1" and not zoe.refused  # the common script, having none of its own
    assert zoe.file == "zoe.VIPLE"
    assert "badkeys.keys: key 1 'w'" in badkeys.refused and "KEY@SECONDS" in badkeys.refused
    assert empty.refused == "the folder holds no VIPLE program (.viple or .xml)"
    assert link.refused == "a symbolic link: hand in the file"
    assert two.refused == "the folder holds 2 programs (a.viple, b.viple): leave one to grade"
    with pytest.raises(FolderError, match="cannot read the folder"):
        find_submissions(tmp_path / "gone")


def test_every_program_file_the_app_runs_is_graded_and_the_rest_is_listed(tmp_path):
    right_wall(tmp_path / "ana.xml", viple3=True)  # VIPLE 3.1: gzip-compressed XML
    (tmp_path / "ana.keys").write_text("a@1\n")
    (tmp_path / "ben").mkdir()
    right_wall(tmp_path / "ben" / "Walls.XML", viple3=True)
    (tmp_path / "ben" / "notes.txt").write_text("my notes")
    (tmp_path / "ben" / ".swap").write_text("")
    right_wall(tmp_path / "cy.viple")
    (tmp_path / "lost.keys").write_text("w@1\n")
    (tmp_path / "readme.txt").write_text("not a program")
    (tmp_path / ".git").mkdir()
    os.mkfifo(tmp_path / "pipe.viple")  # reading it would wait for a writer for ever
    (tmp_path / "dee").mkdir()
    os.mkfifo(tmp_path / "dee" / "walls.viple")

    found = scan_folder(tmp_path)
    assert [(s.student, s.file, s.refused) for s in found.submissions] == [
        ("ana", "ana.xml", ""),
        ("ben", "ben/Walls.XML", ""),
        ("cy", "cy.viple", ""),
        ("dee", "dee", "the folder holds no VIPLE program (.viple or .xml)"),
    ]
    assert found.submissions[0].keys == "a@1"
    fifo = "a named pipe (FIFO), not a plain file: never opened; hand in the file"
    assert found.skipped == [
        Skipped(".git", "a hidden folder (its name starts with a dot)"),
        Skipped("ben/.swap", "a hidden file (its name starts with a dot)"),
        Skipped("ben/notes.txt", "not a VIPLE program (the app runs .viple or .xml files)"),
        Skipped("dee/walls.viple", fifo),
        Skipped("lost.keys", "a key script with no program lost.viple or lost.xml beside it"),
        Skipped("pipe.viple", fifo),
        Skipped("readme.txt", "not a VIPLE program (the app runs .viple or .xml files)"),
    ]


def test_names_are_shown_printable():
    assert shown_name("ana\x1b[2Jx") == "ana?[2Jx"
    assert shown_name("txt\u202eexe") == "txt?exe"
    assert shown_name(os.fsdecode(b"caf\xe9")) == "caf\ufffd"


def test_each_attack_on_its_process_costs_that_program_its_rows_only(tmp_path):
    for name in ("ana", "crash", "deep", "hog", "sleeper"):
        right_wall(tmp_path / f"{name}.viple")
    (tmp_path / "broken.viple").write_text("<Program><Version>4.0")
    plan = Plan(str(tmp_path), (WEB, RANK), profile="web", pilot=HostilePilot)
    seen = []
    rows = grade(
        find_submissions(tmp_path),
        plan,
        jobs=2,
        limits=Limits(deadline=6, memory=400),
        progress=lambda done, total, s: seen.append((done, total, s.student)),
    )
    assert [(r.student, r.maze) for r in rows] == [
        (name, maze)
        for name in ("ana", "broken", "crash", "deep", "hog", "sleeper")
        for maze in ("web.txt", "rank-wall-wins.txt")
    ]
    by = {(r.student, r.maze): r for r in rows}
    ana = by["ana", "web.txt"]
    assert ana.loads and ana.reached_exit and not ana.refusal and ana.errors == 0
    assert ana.time is not None and ana.distance_blocks > 10 and ana.turn_degrees > 90
    assert by["ana", "rank-wall-wins.txt"].reached_exit
    reasons = {r.student: r.refusal for r in rows if r.maze == "web.txt"}
    assert reasons["broken"].startswith("broken.viple: line 1")
    assert reasons["crash"] == "the program's process was ended by SIGSEGV"
    assert "recursion limit" in reasons["deep"]
    assert reasons["hog"] == "used more than 400 MiB of memory, the cap per program (--memory)"
    assert reasons["sleeper"].startswith("stopped after 6 s of wall-clock time")
    for name in ("crash", "deep", "hog", "sleeper"):
        row = by[name, "rank-wall-wins.txt"]  # the runs it never came to share the reason
        assert row.loads and not row.reached_exit and row.refusal == reasons[name]
        assert row.time is None and row.collisions is None
    assert not by["broken", "web.txt"].loads
    assert sorted(done for done, _, _ in seen) == [1, 2, 3, 4, 5, 6]
    assert {s for _, _, s in seen} == {"ana", "broken", "crash", "deep", "hog", "sleeper"}
    assert {total for _, total, _ in seen} == {6}


def test_the_table_as_csv_and_json(tmp_path):
    rows = [
        Row("ana", "ana.viple", "ab" * 32, True, "web.txt", 0, True, 85.733, 57.3, 1566.1, 4, 0),
        Row("=cmd", "=cmd.viple", "cd" * 32, False, "web.txt", 0, refusal="=cmd.viple: bad"),
    ]
    table = list(csv.reader(io.StringIO(csv_text(rows))))
    assert table[0] == list(COLUMNS)
    assert table[1][:8] == ["ana", "ana.viple", "ab" * 32, "yes", "web.txt", "0", "yes", "85.733"]
    # a student's name a spreadsheet would run as a formula is written as text
    assert table[2][:4] == ["'=cmd", "'=cmd.viple", "cd" * 32, "no"]
    assert table[2][7:] == ["", "", "", "", "", "'=cmd.viple: bad"]
    plan = Plan(str(tmp_path), (WEB,), seeds=1, profile="web")
    data = json.loads(json_text(rows, plan, {"lab": "web-simulator", "exercise": "wall-main"}))
    assert data["lab"] == "web-simulator" and data["mazes"] == ["web.txt"]
    assert data["rows"][1]["student"] == "=cmd" and data["rows"][1]["time"] is None
    assert data["rows"][0]["reached_exit"] is True
    lines = summary(rows)
    assert lines[0] == (
        "2 programs, 2 runs: 1 load, 1 reached the exit on every run, 1 refused on some run"
    )
    assert lines[1] == "  =cmd.viple: bad"


def test_the_runs_a_program_finished_before_its_deadline_keep_their_measures(tmp_path):
    right_wall(tmp_path / "later.viple")
    plan = Plan(str(tmp_path), (RANK, WEB), profile="web", pilot=HostilePilot)
    rows = grade(find_submissions(tmp_path), plan, limits=Limits(deadline=3))
    first, second = rows
    assert (first.maze, first.reached_exit, first.refusal) == ("rank-wall-wins.txt", True, "")
    assert second.maze == "web.txt" and not second.reached_exit
    assert second.refusal.startswith("stopped after 3 s of wall-clock time")


def test_a_program_its_interpreter_stops_keeps_its_measures_and_says_why(tmp_path):
    (tmp_path / "spin.viple").write_text(hostile.merge_spin())
    plan = Plan(str(tmp_path), (WEB,), profile="web", max_time=5)
    (row,) = grade(find_submissions(tmp_path), plan, jobs=1, limits=Limits(deadline=60))
    assert row.loads and not row.reached_exit and row.time is not None
    assert row.refusal.startswith("stopped at ") and "one simulated second" in row.refusal
