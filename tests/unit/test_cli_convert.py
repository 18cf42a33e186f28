"""`workbench maze convert`, as a user runs it."""

from tests.files import write
from workbench.cli import main
from workbench.sim.mazeio import load_maze

MICROMOUSE = """\
o---o---o---o
| G         |
o   o---o   o
| S |       |
o---o---o---o
"""
WORKBENCH = """\
---
name: tiny
---
#######
#E....#
#.###.#
#^#...#
#######
"""


def classic_16x16() -> str:
    """Micromouse text of an open 16x16 maze: start walled on its east, goal in the centre."""
    lines = ["o" + "---o" * 16]
    for row in range(16):
        y = 15 - row
        cells = ""
        for x in range(16):
            mark = " S " if (x, y) == (0, 0) else " G " if {x, y} <= {7, 8} else "   "
            east = "|" if x == 15 or (x, y) == (0, 0) else " "
            cells += mark + east
        lines.append("|" + cells)
        lines.append("o" + ("---o" * 16 if y == 0 else "   o" * 15 + "   o"))
    return "\n".join(lines) + "\n"


def test_micromouse_to_workbench(tmp_path, capsys):
    src = write(tmp_path, "tiny.txt", MICROMOUSE)
    out = tmp_path / "tiny.maze"
    assert main(["maze", "convert", src, str(out)]) == 0
    assert out.read_text() == WORKBENCH
    assert f"{out}: written as workbench, 7x5 blocks" in capsys.readouterr().out


def test_workbench_to_micromouse_text(tmp_path):
    src = write(tmp_path, "tiny.maze", WORKBENCH)
    out = tmp_path / "tiny.txt"
    assert main(["maze", "convert", src, str(out), "--to", "micromouse"]) == 0
    assert out.read_text() == MICROMOUSE


def test_maz_output_is_chosen_by_extension_and_reads_back(tmp_path):
    src = write(tmp_path, "open.txt", classic_16x16())
    out = tmp_path / "open.maz"
    assert main(["maze", "convert", src, str(out)]) == 0
    assert len(out.read_bytes()) == 256
    assert load_maze(out).same_layout(load_maze(src))


def test_invalid_input_lists_problems_and_writes_nothing(tmp_path, capsys):
    src = write(tmp_path, "bad.txt", MICROMOUSE.replace("o   o---o   o", "o    ---o   o"))
    out = tmp_path / "out.maze"
    out.write_text("keep me\n")
    assert main(["maze", "convert", src, str(out)]) == 1
    err = capsys.readouterr().err
    assert f"{src}:3:5: missing post at the south-west corner of cell (1, 1)" in err
    assert f"{out}: not written, {src} is not a valid maze" in err
    assert out.read_text() == "keep me\n"


def test_structural_problems_also_stop_the_conversion(tmp_path, capsys):
    src = write(tmp_path, "open.txt", MICROMOUSE.replace("| G         |", "  G         |"))
    out = tmp_path / "out.maze"
    assert main(["maze", "convert", src, str(out)]) == 1
    err = capsys.readouterr().err
    assert f"{src} (as blocks):2:1: open floor on the outer boundary" in err
    assert not out.exists()


def test_maze_that_the_output_format_cannot_hold_is_not_written(tmp_path, capsys):
    src = write(tmp_path, "tiny.txt", MICROMOUSE)
    out = tmp_path / "tiny.maz"
    assert main(["maze", "convert", src, str(out)]) == 1
    err = capsys.readouterr().err
    assert "the maze is 3x2 cells; a .maz file holds exactly 16x16" in err
    assert not out.exists()


def test_from_forces_the_input_format(tmp_path, capsys):
    src = write(tmp_path, "tiny.txt", MICROMOUSE)
    assert main(["maze", "convert", src, str(tmp_path / "o.maze"), "--from", "workbench"]) == 1
    assert f"{src}:1:1: unknown character 'o'" in capsys.readouterr().err


def test_unknown_output_format_is_an_error(tmp_path, capsys):
    src = write(tmp_path, "tiny.txt", MICROMOUSE)
    out = tmp_path / "o.png"
    assert main(["maze", "convert", src, str(out), "--to", "png"]) == 1
    assert "unknown format 'png' (use one of workbench, micromouse, maz)" in (
        capsys.readouterr().err
    )
    assert not out.exists()


def test_lost_start_heading_is_pointed_out(tmp_path, capsys):
    src = write(tmp_path, "right.maze", "#######\n#E....#\n#.#.#.#\n#>#...#\n#######\n")
    out = tmp_path / "right.txt"
    assert main(["maze", "convert", src, str(out), "--to", "micromouse"]) == 0
    assert (
        f"note: micromouse has no start heading; {out} starts facing up, not right"
        in capsys.readouterr().out
    )
