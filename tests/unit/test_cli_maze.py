"""`workbench maze check` and `workbench maze show`, as a user runs them."""

import json

from tests.files import write
from workbench.cli import main

VALID = "---\nname: Tiny\n---\n#####\n#S.E#\n#####\n"
BROKEN = "#####\n#S.X#\n#...\n"


def test_check_valid_file_prints_summary_and_exits_0(tmp_path, capsys):
    path = write(tmp_path, "tiny.txt", VALID)
    assert main(["maze", "check", path]) == 0
    out = capsys.readouterr().out
    assert "valid - Tiny" in out
    assert "size 5x3 blocks, start (1, 1) facing right" in out
    assert "exits (3, 1)" in out
    assert "shortest path to an exit: 2 blocks" in out


def test_check_invalid_file_lists_every_problem_and_exits_1(tmp_path, capsys):
    good = write(tmp_path, "tiny.txt", VALID)
    bad = write(tmp_path, "bad.txt", BROKEN)
    assert main(["maze", "check", good, bad]) == 1
    out = capsys.readouterr().out
    assert f"{bad}:2:4: unknown character 'X'" in out
    assert "valid - Tiny" in out


def test_check_structural_problems_exit_1(tmp_path, capsys):
    path = write(tmp_path, "open.txt", "#####\n#S..#\n#...\n#####\n")
    assert main(["maze", "check", path]) == 1
    out = capsys.readouterr().out
    assert "INVALID" in out and f"{path}:3:5: open floor on the outer boundary" in out


def test_check_json_is_one_object_per_file(tmp_path, capsys):
    path = write(tmp_path, "tiny.txt", VALID)
    bad = write(tmp_path, "bad.txt", BROKEN)
    assert main(["maze", "check", "--json", path, bad]) == 1
    lines = [json.loads(line) for line in capsys.readouterr().out.splitlines()]
    assert lines[0]["valid"] is True and lines[0]["shortest_path"] == 2
    assert lines[0]["start"] == [1, 1] and lines[0]["exits"] == [[3, 1]]
    assert lines[1]["valid"] is False
    assert lines[1]["problems"][0] == {
        "source": bad,
        "line": 2,
        "col": 4,
        "message": "unknown character 'X'",
        "hint": "use # wall, . floor, S start, E exit",
    }


def test_check_missing_file_exits_1(tmp_path, capsys):
    assert main(["maze", "check", str(tmp_path / "nope.txt")]) == 1
    assert "cannot read" in capsys.readouterr().out


def test_show_ascii_picture(tmp_path, capsys):
    path = write(tmp_path, "tiny.txt", VALID)
    assert main(["maze", "show", path]) == 0
    assert capsys.readouterr().out.splitlines() == [
        "##########",
        "##>   E ##",
        "##########",
    ]


def test_show_unicode_outlines_walls(tmp_path, capsys):
    path = write(tmp_path, "tiny.txt", VALID)
    assert main(["maze", "show", "--unicode", path]) == 0
    assert capsys.readouterr().out.splitlines() == [
        "┌───────┐",
        "│ ▶   E │",
        "└───────┘",
    ]


def test_show_invalid_file_reports_to_stderr(tmp_path, capsys):
    path = write(tmp_path, "bad.txt", BROKEN)
    assert main(["maze", "show", path]) == 1
    assert "unknown character 'X'" in capsys.readouterr().err


def test_no_command_shows_the_default_maze(capsys):
    assert main([]) == 0
    out = capsys.readouterr().out
    assert "Unity default" in out and "free exploration" in out
