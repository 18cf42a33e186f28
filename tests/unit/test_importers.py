"""Micromouse importers and writers: micromouseonline text, mms map/num, binary .maz."""

import pytest

from tests.files import write
from workbench.sim.maz import format_maz, parse_maz
from workbench.sim.maze import Maze, MazeError
from workbench.sim.mazefile import parse_maze
from workbench.sim.mazeio import detect_format, load_maze, save_maze
from workbench.sim.micromouse import (
    format_micromouse,
    parse_micromouse,
    parse_mms_map,
    parse_mms_num,
)
from workbench.sim.wallmaze import E, N, S, W, WallMaze, from_blocks, to_blocks, wall_problems

# A 3x2-cell maze: goal top-left, start bottom-left, one wall between the bottom-left cells.
MICROMOUSE = """\
o---o---o---o
| G         |
o   o---o   o
| S |       |
o---o---o---o
"""
MMS_MAP = MICROMOUSE.replace("o", "+").replace(" G ", "   ").replace(" S ", "   ")
MMS_NUM = """\
0 0 0 1 1 1
0 1 1 0 0 1
1 0 1 0 1 1
1 1 1 0 1 0
2 0 0 1 1 0
2 1 1 1 0 0
"""
BLOCKS = (
    "#######",
    "#.....#",
    "#.###.#",
    "#.#...#",
    "#######",
)


def problems(exc_info) -> list[str]:
    return [str(p) for p in exc_info.value.problems]


# -- micromouseonline text -------------------------------------------------------------------


def test_micromouse_text_becomes_the_exact_block_grid(tmp_path):
    maze = load_maze(write(tmp_path, "tiny.txt", MICROMOUSE))
    assert maze.rows == BLOCKS
    assert maze.start == (1, 3) and maze.heading == "up"
    assert maze.exits == ((1, 1),)
    assert maze.name == "tiny"
    assert maze.validate() == []


def test_micromouse_cells_have_bottom_origin_wall_bits():
    wm = parse_micromouse(MICROMOUSE)
    assert (wm.width, wm.height) == (3, 2)
    assert wm.bits(0, 0) == E | S | W
    assert wm.bits(1, 1) == N | S
    assert wm.start == (0, 0) and wm.goals == ((0, 1),)


def test_start_heading_is_the_only_open_side():
    text = "o---o---o\n| S     |\no---o---o\n"
    maze = to_blocks(parse_micromouse(text))
    assert maze.start == (1, 1) and maze.heading == "right"


def test_micromouse_without_s_starts_bottom_left_with_no_exits():
    text = MICROMOUSE.replace(" G ", "   ").replace(" S ", "   ")
    maze = to_blocks(parse_micromouse(text))
    assert maze.start == (1, 3) and maze.exits == ()
    assert maze.validate() == []
    assert maze.notes() == ["no exits: free exploration (runs end at their time limit)"]


def test_any_mark_at_the_wall_middle_is_a_wall_and_trailing_blank_lines_are_fine():
    text = MICROMOUSE.replace("o   o---o   o", "o   o===o   o") + "\n\n"
    assert to_blocks(parse_micromouse(text)).rows == BLOCKS


def test_missing_post_names_the_cell():
    text = MICROMOUSE.replace("o   o---o   o", "o    ---o   o")
    with pytest.raises(MazeError) as info:
        parse_micromouse(text, "m.txt")
    assert problems(info) == [
        "m.txt:3:5: missing post at the south-west corner of cell (1, 1) "
        "(put 'o' at every corner, also between open cells)"
    ]


def test_missing_post_on_the_outer_corner_names_the_corner_cell():
    text = MICROMOUSE.replace("o---o---o---o\n| G", "o---o---o--- \n| G", 1)
    with pytest.raises(MazeError) as info:
        parse_micromouse(text, "m.txt")
    assert problems(info) == [
        "m.txt:1:13: missing post at the north-east corner of cell (2, 1) "
        "(put 'o' at every corner, also between open cells)"
    ]


def test_ragged_lines_are_errors_with_line_and_column():
    lines = MICROMOUSE.splitlines()
    lines[3] = lines[3][:-1]
    lines[1] += "  x"
    with pytest.raises(MazeError) as info:
        parse_micromouse("\n".join(lines), "m.txt")
    assert problems(info) == [
        "m.txt:2:14: line is 16 characters long, longer than the first line (13) "
        "(every line of the maze has the same length: remove the extra characters)",
        "m.txt:4:13: line is 12 characters long, shorter than the first line (13) "
        "(every line of the maze has the same length: pad it with spaces)",
    ]


def test_wrong_line_count_is_an_error():
    text = "\n".join(MICROMOUSE.splitlines()[:4])
    with pytest.raises(MazeError) as info:
        parse_micromouse(text, "m.txt")
    (message,) = problems(info)
    assert message.startswith("m.txt:4:1: the maze has 4 lines;")
    assert "needs an odd number" in message


def test_cells_not_three_characters_wide_are_an_error():
    with pytest.raises(MazeError) as info:
        parse_micromouse("o--o\n|  |\no--o\n", "m.txt")
    (message,) = problems(info)
    assert message.startswith("m.txt:1:4: the first line is 4 characters long;")
    assert "4 x cells + 1" in message


def test_unknown_cell_character_and_two_starts_are_reported_together():
    text = MICROMOUSE.replace(" G ", " S ").replace("| S |       |", "| S | X     |")
    with pytest.raises(MazeError) as info:
        parse_micromouse(text, "m.txt")
    assert problems(info) == [
        "m.txt:4:7: unknown character 'X' in cell (1, 0) "
        "(a cell holds spaces, S for the start or G for a goal)",
        "m.txt:2:3: cell (0, 1) is one of 2 start cells (keep one S)",
        "m.txt:4:3: cell (0, 0) is one of 2 start cells (keep one S)",
    ]


def test_wall_segment_without_a_middle_mark_is_not_guessed():
    text = MICROMOUSE.replace("o   o---o   o", "o   o-  o   o")
    with pytest.raises(MazeError) as info:
        parse_micromouse(text, "m.txt")
    assert problems(info) == [
        "m.txt:3:6: wall segment '-  ' has nothing at its middle "
        "(write '---' for a wall or only spaces for none)"
    ]


# -- mms map and num ---------------------------------------------------------------------------


def test_mms_map_becomes_the_same_blocks_starting_bottom_left(tmp_path):
    maze = load_maze(write(tmp_path, "tiny.map", MMS_MAP))
    assert maze.rows == BLOCKS
    assert maze.start == (1, 3) and maze.heading == "up" and maze.exits == ()


def test_mms_map_takes_cell_widths_from_the_first_line():
    text = "+-----+--+\n|     |  |\n+-----+--+\n"
    wm = parse_mms_map(text)
    assert (wm.width, wm.height) == (2, 1)
    assert wm.bits(0, 0) == N | E | S | W and wm.bits(1, 0) == N | E | S | W


def test_mms_map_missing_post_is_an_error():
    with pytest.raises(MazeError) as info:
        parse_mms_map(MMS_MAP.replace("+   +---+   +", "+   +---    +"), "m.map")
    assert problems(info) == [
        "m.map:3:9: missing post at the south-west corner of cell (2, 1) "
        "(put '+' at every corner, also between open cells)"
    ]


@pytest.mark.parametrize(
    ("first", "expected"),
    [
        (
            "-+---+",
            "m.map:1:1: the first line must start with a '+' post (draw the top wall first)",
        ),
        ("+---+--", "m.map:1:7: the first line must end with a '+' post"),
        ("+---++", "m.map:1:6: two posts with no cell between them"),
    ],
)
def test_mms_map_first_line_shape_errors(first, expected):
    with pytest.raises(MazeError) as info:
        parse_mms_map(f"{first}\n|   |\n+---+\n", "m.map")
    assert problems(info)[0].startswith(expected)


def test_wrong_character_at_a_post_is_named():
    with pytest.raises(MazeError) as info:
        parse_micromouse(MICROMOUSE.replace("o   o---o   o", "o   |---o   o"), "m.txt")
    assert problems(info) == [
        "m.txt:3:5: '|' instead of a post at the south-west corner of cell (1, 1) "
        "(put 'o' at every corner, also between open cells)"
    ]


def test_mms_num_becomes_the_same_blocks(tmp_path):
    maze = load_maze(write(tmp_path, "tiny.num", MMS_NUM))
    assert maze.rows == BLOCKS and maze.start == (1, 3) and maze.exits == ()


def test_mms_num_disagreeing_walls_name_both_cells_and_the_line():
    text = MMS_NUM.replace("0 0 0 1 1 1", "0 0 0 0 1 1")
    with pytest.raises(MazeError) as info:
        parse_mms_num(text, "m.num")
    assert problems(info) == [
        "m.num:3:1: cell (1, 0) has a wall on its west side but cell (0, 0) has none on its "
        "east side (give both cells the wall or remove it from both)"
    ]


def test_mms_num_missing_and_duplicate_cells():
    text = MMS_NUM.replace("1 1 1 0 1 0\n", "0 1 1 0 0 1\n")
    with pytest.raises(MazeError) as info:
        parse_mms_num(text, "m.num")
    assert problems(info) == [
        "m.num:4:1: cell (0, 1) is listed again; it was first on line 2 (keep one line per cell)",
        "m.num: cell (1, 1) is missing from the 3x2 maze (add a line '1 1 N E S W' for it)",
    ]


def test_mms_num_bad_numbers_name_line_and_column():
    text = "0 0 1 1 1 1\n0 x 1 1 1 1\n1 0 1 2 1 1\n1 1 1 1\n"
    with pytest.raises(MazeError) as info:
        parse_mms_num(text, "m.num")
    assert problems(info)[:3] == [
        "m.num:2:3: y is 'x', not a whole number (use digits only)",
        "m.num:3:7: E wall is 2; walls are 0 (open) or 1 (wall) (write 0 or 1)",
        "m.num:4:1: expected six numbers 'x y N E S W', found 4 fields (write one cell per "
        "line: its x, y and 0/1 for the north, east, south, west walls)",
    ]


def test_mms_num_rejects_huge_coordinates_and_empty_files():
    with pytest.raises(MazeError) as info:
        parse_mms_num("0 500 1 1 1 1\n", "m.num")
    assert problems(info) == [
        "m.num:1:3: y is 500; a maze has at most 99 cells a side (check the coordinate)"
    ]
    with pytest.raises(MazeError, match="the file lists no cells"):
        parse_mms_num("\n\n", "m.num")


# -- the wall model ------------------------------------------------------------------------


def test_wall_check_reports_every_disagreement_and_to_blocks_refuses():
    walls = [N | E | S | W] * 4
    walls[0] = N | S | W  # (0, 0) open east, (1, 0) walled west
    walls[3] = N | E  # (1, 1) open south and west
    wm = WallMaze(2, 2, tuple(walls), source="w")
    found = [str(p) for p in wall_problems(wm)]
    assert found == [
        "w: cell (1, 0) has a wall on its west side but cell (0, 0) has none on its east side "
        "(give both cells the wall or remove it from both)",
        "w: cell (1, 0) has a wall on its north side but cell (1, 1) has none on its south side "
        "(give both cells the wall or remove it from both)",
        "w: cell (0, 1) has a wall on its east side but cell (1, 1) has none on its west side "
        "(give both cells the wall or remove it from both)",
    ]
    with pytest.raises(MazeError):
        to_blocks(wm)


def test_from_blocks_round_trips_the_wall_maze():
    wm = parse_micromouse(MICROMOUSE)
    back = from_blocks(to_blocks(wm))
    assert (back.walls, back.start, back.goals) == (wm.walls, wm.start, wm.goals)


def test_from_blocks_says_why_a_maze_does_not_fit():
    maze = parse_maze("#######\n#S.#..#\n##..###\nE.....#\n#######\n", "b.txt")
    with pytest.raises(MazeError) as info:
        from_blocks(maze)
    assert problems(info) == [
        "b.txt:2:4: wall block inside a micromouse cell "
        "(make it . floor: cells are the blocks between the posts)",
        "b.txt:3:3: floor at a corner post between micromouse cells "
        "(make it a # wall: every second block of every second row is a post)",
        "b.txt:4:1: exit on the outer boundary cannot be written as a micromouse goal cell "
        "(move the exit inside the maze, onto a cell block)",
    ]


def test_from_blocks_rejects_even_sizes_and_starts_between_cells():
    with pytest.raises(MazeError, match="6x3 blocks; a micromouse maze has an odd width"):
        from_blocks(parse_maze("######\n#S...#\n######\n"))
    with pytest.raises(MazeError, match="start is not on a micromouse cell"):
        from_blocks(parse_maze("#####\n#.S.#\n#####\n"))


# -- writing micromouse text -------------------------------------------------------------------


def test_format_micromouse_writes_posts_walls_start_and_goals():
    maze = parse_maze("#######\n#E....#\n#.###.#\n#^#...#\n#######\n")
    assert format_micromouse(maze) == MICROMOUSE


def test_format_micromouse_refuses_a_maze_off_the_cell_grid():
    with pytest.raises(MazeError, match="exit between two cells"):
        format_micromouse(parse_maze("#######\n#SE...#\n#######\n"))


# -- binary .maz -------------------------------------------------------------------------------


def classic_walls() -> dict[tuple[int, int], int]:
    """A 16x16 maze: outer walls plus one wall east of the start cell."""
    walls = {}
    for x in range(16):
        for y in range(16):
            bits = (N if y == 15 else 0) | (S if y == 0 else 0)
            bits |= (W if x == 0 else 0) | (E if x == 15 else 0)
            walls[(x, y)] = bits
    walls[(0, 0)] |= E
    walls[(1, 0)] |= W
    return walls


def maz_bytes(walls, row_major=False) -> bytes:
    data = bytearray(256)
    for (x, y), bits in walls.items():
        data[16 * (15 - y) + x if row_major else 16 * x + y] = bits
    return bytes(data)


def test_classic_maz_starts_bottom_left_facing_up_with_the_centre_goal(tmp_path):
    maze = load_maze(write(tmp_path, "open.maz", maz_bytes(classic_walls())))
    assert (maze.width, maze.height) == (33, 33)
    assert maze.start == (1, 31) and maze.heading == "up"
    assert maze.exits == ((15, 15), (17, 15), (15, 17), (17, 17))
    assert maze.rows[31][:4] == "#.#."
    assert maze.validate() == []


def test_row_major_maz_variant_is_detected(tmp_path):
    classic = load_maze(write(tmp_path, "a.maz", maz_bytes(classic_walls())))
    rows = load_maze(write(tmp_path, "b.maz", maz_bytes(classic_walls(), row_major=True)))
    assert rows.same_layout(classic)


def test_maz_consistent_neither_way_says_how_many_walls_disagree():
    walls = classic_walls()
    walls[(5, 5)] |= N
    with pytest.raises(MazeError) as info:
        parse_maz(maz_bytes(walls), "bad.maz")
    (message,) = problems(info)
    assert message.startswith("bad.maz: the walls do not fit together in either layout;")
    assert "1 when read column by column from the bottom-left (classic .maz)" in message
    assert "when read row by row from the top-left" in message


def test_maz_of_the_wrong_size_says_the_size_found(tmp_path):
    with pytest.raises(MazeError) as info:
        load_maze(write(tmp_path, "short.maz", bytes(200)), "maz")
    assert "this one is 200 bytes" in problems(info)[0]
    with pytest.raises(
        MazeError, match=r"neither UTF-8 text nor a \.maz maze \(256 bytes; this one is 100 bytes\)"
    ):
        load_maze(write(tmp_path, "junk.bin", bytes(range(100))))


def test_format_maz_round_trips_and_refuses_other_mazes(tmp_path):
    data = maz_bytes(classic_walls())
    maze = load_maze(write(tmp_path, "a.maz", data))
    assert format_maz(maze) == data
    with pytest.raises(MazeError, match=r"3x2 cells; a \.maz file holds exactly 16x16"):
        format_maz(to_blocks(parse_micromouse(MICROMOUSE)))
    moved = maze.with_exit(15, 15, present=False).with_start(3, 31)
    with pytest.raises(MazeError) as info:
        format_maz(moved)
    start, goals = problems(info)
    assert "the start is cell (1, 0) facing up; a .maz maze always starts in cell (0, 0)" in start
    assert "the goal cells are (7, 7), (8, 7), (8, 8)" in goals


# -- detection and saving -------------------------------------------------------------------


def test_format_is_detected_from_content():
    assert detect_format(MICROMOUSE.encode()) == "micromouse"
    assert detect_format(MMS_MAP.encode()) == "mms-map"
    assert detect_format(MMS_NUM.encode()) == "mms-num"
    assert detect_format(b"#####\n#S.E#\n#####\n") == "workbench"
    assert detect_format(maz_bytes(classic_walls())) == "maz"


def test_from_forces_the_format(tmp_path):
    path = write(tmp_path, "tiny.txt", MICROMOUSE)
    with pytest.raises(MazeError, match="unknown character 'o'"):
        load_maze(path, "workbench")
    with pytest.raises(MazeError, match="unknown format 'png'"):
        load_maze(path, "png")


def test_save_maze_writes_each_format_atomically(tmp_path):
    maze = load_maze(write(tmp_path, "in.txt", MICROMOUSE))
    save_maze(tmp_path / "out.mm", maze, "micromouse")
    save_maze(tmp_path / "out.txt", maze)
    assert (tmp_path / "out.mm").read_text() == MICROMOUSE
    assert load_maze(tmp_path / "out.txt").same_layout(maze)
    with pytest.raises(MazeError, match="unknown format 'mms-num'"):
        save_maze(tmp_path / "out.num", maze, "mms-num")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["in.txt", "out.mm", "out.txt"]


def test_save_maz_writes_bytes(tmp_path):
    data = maz_bytes(classic_walls())
    maze = load_maze(write(tmp_path, "a.maz", data))
    save_maze(tmp_path / "b.maz", maze, "maz")
    assert (tmp_path / "b.maz").read_bytes() == data
    assert isinstance(load_maze(tmp_path / "b.maz"), Maze)
