"""The block maze model: editing, shortest paths, digests."""

from workbench.sim.maze import Maze, default_heading
from workbench.sim.mazefile import parse_maze

ROOM = parse_maze(
    """\
#######
#S....#
#.###.#
#...#E#
#######
"""
)


def test_shortest_path_takes_the_short_way():
    assert ROOM.shortest_path_length() == 6


def test_shortest_path_picks_the_nearest_exit():
    maze = ROOM.with_exit(1, 3)
    assert maze.shortest_path_length() == 2


def test_walling_off_an_exit_makes_it_unreachable():
    maze = ROOM.with_block(5, 2, wall=True)
    assert maze.shortest_path_length() is None
    assert [p.message for p in maze.validate()] == ["exit cannot be reached from the start"]


def test_wall_over_an_exit_removes_the_exit():
    maze = ROOM.with_block(5, 3, wall=True)
    assert maze.exits == ()


def test_start_in_a_wall_is_reported():
    maze = ROOM.with_start(3, 2)
    assert "start is inside a wall block" in [p.message for p in maze.validate()]


def test_editing_returns_new_mazes_and_keeps_the_original():
    edited = ROOM.with_block(2, 1, wall=True)
    assert ROOM.rows[1] == "#.....#" and edited.rows[1] == "#.#...#"
    assert edited.digest() != ROOM.digest()
    assert ROOM.with_block(2, 1, wall=False).digest() == ROOM.digest()


def test_default_heading_faces_the_only_opening():
    maze = Maze(rows=("###", "#.#", "#.#", "###"))
    assert default_heading(maze, (1, 2)) == "up"
    assert default_heading(maze, (1, 1)) == "down"
    open_room = Maze(rows=("####", "#..#", "#..#", "####"))
    assert default_heading(open_room, (1, 1)) == "up"


def test_start_on_an_exit_is_reported():
    maze = ROOM.with_exit(1, 1)
    assert "start is on an exit" in [p.message for p in maze.validate()]


def test_mirrored_maze_swaps_left_and_right():
    maze = Maze(rows=("#####", "#...#", "#.###"), start=(1, 1), heading="right", exits=((1, 2),))
    mirror = maze.mirrored()
    assert mirror.rows == ("#####", "#...#", "###.#")
    assert (mirror.start, mirror.heading, mirror.exits) == ((3, 1), "left", ((3, 2),))
    assert mirror.mirrored().same_layout(maze)
