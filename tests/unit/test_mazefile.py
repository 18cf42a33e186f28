"""The workbench maze text format: reading, writing and every error path."""

import pytest

from workbench.sim.maze import MazeError
from workbench.sim.mazefile import format_maze, parse_maze, write_maze
from workbench.sim.mazeio import load_maze

CORRIDOR = """\
---
name: Corridor
description: straight
profile: unity
cell: 2
---
#######
#S...E#
#######
"""


def problems_of(text: str) -> list[str]:
    with pytest.raises(MazeError) as info:
        parse_maze(text, source="x.txt")
    return [str(p) for p in info.value.problems]


def test_front_matter_and_grid_are_read():
    maze = parse_maze(CORRIDOR, source="c.txt")
    assert (maze.name, maze.description, maze.profile, maze.cell) == (
        "Corridor",
        "straight",
        "unity",
        2.0,
    )
    assert maze.rows == ("#######", "#.....#", "#######")
    assert maze.start == (1, 1) and maze.heading == "right"
    assert maze.exits == ((5, 1),)
    assert maze.body_line == 7
    assert maze.validate() == []


@pytest.mark.parametrize(
    ("char", "heading"), [("^", "up"), (">", "right"), ("v", "down"), ("<", "left"), ("S", "right")]
)
def test_start_characters_give_headings(char, heading):
    maze = parse_maze(f"###\n#{char}#\n###\n")
    assert maze.heading == heading and maze.start == (1, 1)


def test_unknown_character_names_line_column_and_fix():
    text = "---\nname: x\n---\n#####\n#S.X#\n#####\n"
    assert problems_of(text) == [
        "x.txt:5:4: unknown character 'X' (use # wall, . floor, S start, E exit)"
    ]


def test_every_problem_is_reported_at_once():
    text = "#####\n#S\tX#\n#S..#\n#####\n"
    found = problems_of(text)
    assert "x.txt:2:3: tab character (replace tabs with spaces or .)" in found
    assert any(p.startswith("x.txt:2:4: unknown character 'X'") for p in found)
    assert sum("one of 2 starts" in p for p in found) == 2


def test_short_lines_are_padded_with_floor_and_break_the_boundary():
    maze = parse_maze("#####\n#S\n#####\n", source="x.txt")
    assert maze.rows[1] == "#...."
    assert [str(p) for p in maze.validate()] == [
        "x.txt:2:5: open floor on the outer boundary: the robot could leave the maze "
        "(make it a # wall or an E exit)"
    ]


def test_exit_on_the_boundary_is_an_opening():
    maze = parse_maze("#####\n#S..E\n#####\n")
    assert maze.validate() == []
    assert maze.shortest_path_length() == 3


def test_unreachable_exit_is_reported_at_its_position():
    maze = parse_maze("#######\n#S.#.E#\n#######\n", source="x.txt")
    assert [str(p) for p in maze.validate()] == [
        "x.txt:2:6: exit cannot be reached from the start (open a path to it or remove the E)"
    ]


def test_no_start_is_reported():
    maze = parse_maze("####\n#..#\n####\n", source="x.txt")
    assert [p.message for p in maze.validate()] == ["no start"]


def test_maze_without_exits_is_valid_and_says_so():
    maze = parse_maze("####\n#S.#\n####\n")
    assert maze.validate() == []
    assert maze.notes() == ["no exits: free exploration (runs end at their time limit)"]
    assert maze.shortest_path_length() is None


def test_oversized_maze_is_rejected_before_its_blocks_are_read():
    row = "#" * 201
    with pytest.raises(MazeError) as info:
        parse_maze("\n".join([row, "#S" + "." * 198 + "#", row]))
    (problem,) = info.value.problems
    assert "201 blocks wide, wider than the largest maze (200x200 blocks)" in problem.message
    assert (problem.line, problem.column) == (1, 201)
    tall = "\n".join(["#" * 5] * 201)
    with pytest.raises(MazeError, match=r"<maze>:201:1: the grid has 201 rows"):
        parse_maze(tall)


@pytest.mark.parametrize(
    ("header", "expected"),
    [
        ("---\nname: [unclosed\n---\n", "front matter is not valid YAML"),
        ("---\nname: x\n", "front matter is never closed"),
        ("---\ncolour: red\n---\n", "unknown front matter key 'colour'"),
        ("---\nprofile: lego\n---\n", "unknown profile 'lego'"),
        ("---\ncell: -1\n---\n", "cell must be a positive number"),
        ("---\n- a\n- b\n---\n", "front matter must be key: value lines"),
    ],
)
def test_front_matter_errors(header, expected):
    found = problems_of(header + "###\n#S#\n###\n")
    assert any(expected in p for p in found), found


def test_unknown_key_points_at_its_line():
    found = problems_of("---\nname: a\ncolour: red\n---\n###\n#S#\n###\n")
    assert found[0].startswith("x.txt:3:1: unknown front matter key 'colour'")


def test_empty_grid_is_an_error():
    assert problems_of("---\nname: a\n---\n\n") == [
        "x.txt: no maze grid found (draw the maze with # and . after the header)"
    ]


def test_format_round_trips(tmp_path):
    maze = parse_maze(CORRIDOR)
    path = tmp_path / "out.txt"
    write_maze(path, maze)
    again = load_maze(path)
    assert again == maze
    assert format_maze(again) == path.read_text()


def test_atomic_write_leaves_no_temporary_files(tmp_path):
    path = tmp_path / "m.txt"
    write_maze(path, parse_maze(CORRIDOR))
    write_maze(path, parse_maze(CORRIDOR))
    assert [p.name for p in tmp_path.iterdir()] == ["m.txt"]


def test_unreadable_and_binary_files_are_clear_errors(tmp_path):
    with pytest.raises(MazeError, match="cannot read"):
        load_maze(tmp_path / "missing.txt")
    bad = tmp_path / "bad.txt"
    bad.write_bytes(b"\xff\xfe\x00#")
    with pytest.raises(MazeError, match="UTF-8"):
        load_maze(bad)


def test_name_defaults_to_file_stem(tmp_path):
    path = tmp_path / "little.txt"
    path.write_text("###\n#S#\n###\n")
    assert load_maze(path).name == "little"


def test_saved_files_keep_their_permissions(tmp_path):
    path = tmp_path / "m.txt"
    path.write_text("old")
    path.chmod(0o640)
    write_maze(path, parse_maze(CORRIDOR))
    assert path.stat().st_mode & 0o777 == 0o640
    fresh = tmp_path / "fresh.txt"
    write_maze(fresh, parse_maze(CORRIDOR))
    assert fresh.stat().st_mode & 0o044 == 0o044  # readable by others, like any new file
