"""Seeded maze generation (`workbench.sim.generate`, `workbench maze generate`) and the bundled
mazes."""

from collections import deque
from pathlib import Path

import pytest

from workbench.cli import main
from workbench.sim.generate import generate
from workbench.sim.maze import HEADINGS, PROFILES
from workbench.sim.mazefile import parse_maze
from workbench.sim.mazeio import load_maze

MAZE_DIR = Path(__file__).resolve().parents[2] / "mazes"
SIZES = [(1, 1), (1, 6), (7, 1), (2, 2), (5, 5), (16, 16), (13, 8)]


def cells(maze):
    """Cell blocks of a generated maze: (cx, cy) -> block (2cx+1, 2cy+1)."""
    w, h = (maze.width - 1) // 2, (maze.height - 1) // 2
    return [(cx, cy) for cy in range(h) for cx in range(w)]


def cell_links(maze):
    """Open passages between neighbouring cells, as {cell: [neighbour cells]}."""
    links = {c: [] for c in cells(maze)}
    for cx, cy in links:
        for dx, dy in ((1, 0), (0, 1)):
            n = (cx + dx, cy + dy)
            if n in links and not maze.is_wall(2 * cx + 1 + dx, 2 * cy + 1 + dy):
                links[(cx, cy)].append(n)
                links[n].append((cx, cy))
    return links


def reachable(links, origin=(0, 0)):
    seen = {origin}
    queue = deque([origin])
    while queue:
        for n in links[queue.popleft()]:
            if n not in seen:
                seen.add(n)
                queue.append(n)
    return seen


def dead_ends(maze):
    return [c for c, ns in cell_links(maze).items() if len(ns) == 1]


# -- determinism --------------------------------------------------------------------------


@pytest.mark.parametrize("style", ["perfect", "braid"])
def test_same_seed_gives_the_same_maze(style):
    a = generate(12, 9, 7, style)
    b = generate(12, 9, 7, style)
    assert a == b
    assert a.name == f"{style} 12x9 seed 7"


@pytest.mark.parametrize("style", ["perfect", "braid"])
def test_different_seeds_give_different_mazes(style):
    layouts = {generate(12, 9, seed, style).rows for seed in range(10)}
    assert len(layouts) == 10


def test_a_seed_gives_the_same_maze_on_every_machine():
    maze = generate(4, 3, 7)
    assert maze.rows == (
        "#########",
        "#...#.#.#",
        "#.#.#.#.#",
        "#.#.....#",
        "#.#####.#",
        "#.#.....#",
        "###.#####",
    )
    assert maze.start == (1, 5) and maze.heading == "up"
    assert maze.exits == ((3, 6),)


# -- shape --------------------------------------------------------------------------------


@pytest.mark.parametrize(("width", "height"), SIZES)
@pytest.mark.parametrize("style", ["perfect", "braid"])
@pytest.mark.parametrize("exit", ["boundary", "center", "none"])
def test_every_generated_maze_is_valid(width, height, style, exit):
    if (width, height, exit) == (1, 1, "center"):
        return  # the only cell is the start: refused, see test_centre_exit_never_lands_on_the_start
    for seed in range(3):
        maze = generate(width, height, seed, style, exit)
        assert maze.validate() == []
        assert (maze.width, maze.height) == (2 * width + 1, 2 * height + 1)


def test_cells_are_floor_and_posts_are_wall():
    maze = generate(9, 6, 3, "braid")
    for y in range(maze.height):
        for x in range(maze.width):
            if x % 2 == 0 and y % 2 == 0:
                assert maze.is_wall(x, y), (x, y)
            if x % 2 == 1 and y % 2 == 1:
                assert not maze.is_wall(x, y), (x, y)


@pytest.mark.parametrize("style", ["perfect", "braid"])
@pytest.mark.parametrize(("width", "height"), [(2, 2), (6, 5), (16, 16), (1, 6), (7, 1)])
def test_start_is_the_bottom_left_cell_in_a_corridor_facing_its_one_opening(style, width, height):
    headings = set()
    for seed in range(12):
        maze = generate(width, height, seed, style)
        sx, sy = maze.start
        assert maze.start == (1, 2 * height - 1)
        open_sides = [h for h, (dx, dy) in HEADINGS.items() if not maze.is_wall(sx + dx, sy + dy)]
        assert open_sides == [maze.heading], seed
        # the robot has a wall on either hand: a wall follower starts on the outer wall
        dx, dy = HEADINGS[maze.heading]
        assert maze.is_wall(sx - dy, sy + dx) and maze.is_wall(sx + dy, sy - dx)
        headings.add(maze.heading)
    one_way = "up" if width == 1 else "right"
    assert headings <= ({"up", "right"} if width > 1 and height > 1 else {one_way})


def test_closing_the_start_corner_keeps_every_cell_reachable_and_the_maze_perfect():
    for seed in range(20):
        maze = generate(8, 6, seed, "perfect", "none")
        links = cell_links(maze)
        assert len(links[(0, 5)]) == 1
        assert len(reachable(links, (0, 5))) == 48
        assert sum(len(ns) for ns in links.values()) // 2 == 47


# -- perfect and braid ----------------------------------------------------------------------


@pytest.mark.parametrize(("width", "height"), [*SIZES, (99, 99)])
def test_perfect_maze_has_exactly_one_path_between_cells(width, height):
    for seed in range(3):
        links = cell_links(generate(width, height, seed, "perfect", "none"))
        passages = sum(len(ns) for ns in links.values()) // 2
        assert passages == width * height - 1
        assert len(reachable(links)) == width * height


@pytest.mark.parametrize(("width", "height"), [(2, 2), (3, 7), (10, 10), (25, 14)])
def test_braid_maze_has_no_dead_ends_but_the_start_and_has_loops(width, height):
    for seed in range(5):
        maze = generate(width, height, seed, "braid", "none")
        links = cell_links(maze)
        start = (0, height - 1)
        if width > 2 and height > 2:
            assert dead_ends(maze) == [start]
        else:  # the start's neighbour may have no wall to open but the start's
            assert start in dead_ends(maze) and len(dead_ends(maze)) <= 2
        assert len(reachable(links)) == width * height
        if width > 2 and height > 2:
            assert sum(len(ns) for ns in links.values()) // 2 > width * height - 1


def test_braid_corridor_one_cell_wide_keeps_only_its_two_ends():
    maze = generate(1, 6, 4, "braid", "none")
    assert sorted(dead_ends(maze)) == [(0, 0), (0, 5)]


def test_braid_has_far_fewer_dead_ends_than_perfect():
    perfect = generate(20, 20, 11, "perfect")
    braid = generate(20, 20, 11, "braid")
    assert len(dead_ends(perfect)) > 20
    assert dead_ends(braid) == [(0, 19)]


def test_largest_maze_is_generated():
    maze = generate(99, 99, 5, "braid")
    assert (maze.width, maze.height) == (199, 199)
    assert maze.validate() == []


# -- exits ----------------------------------------------------------------------------------


@pytest.mark.parametrize("style", ["perfect", "braid"])
def test_boundary_exit_is_an_opening_beside_the_farthest_edge_cell(style):
    for seed in range(8):
        maze = generate(7, 6, seed, style, "boundary")
        assert len(maze.exits) == 1
        ex, ey = maze.exits[0]
        assert ex in (0, maze.width - 1) or ey in (0, maze.height - 1)
        dist = maze.distances_from(maze.start)
        edge_cells = [
            (2 * cx + 1, 2 * cy + 1) for cx, cy in cells(maze) if cx in (0, 6) or cy in (0, 5)
        ]
        (inside,) = list(maze.floor_neighbours((ex, ey)))
        assert dist[inside] == max(dist[c] for c in edge_cells)
        assert maze.shortest_path_length() == dist[inside] + 1


def test_center_exit_of_an_odd_maze_is_the_centre_cell():
    maze = generate(5, 5, 1, exit="center")
    assert maze.exits == ((5, 5),)


def test_center_exit_of_an_even_maze_is_the_micromouse_goal():
    maze = generate(16, 16, 7, exit="center")
    assert maze.exits == ((15, 15), (17, 15), (15, 17), (17, 17))
    assert maze.shortest_path_length() is not None


def test_center_exit_of_a_mixed_maze_is_the_two_middle_cells():
    assert generate(4, 5, 1, exit="center").exits == ((3, 5), (5, 5))
    assert generate(5, 4, 1, exit="center").exits == ((5, 3), (5, 5))


def test_no_exit_means_free_exploration():
    maze = generate(6, 6, 2, exit="none")
    assert maze.exits == ()
    assert "free exploration" in maze.notes()[0]
    assert "no exit" in maze.description


# -- bad arguments ----------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("args", "message"),
    [
        ((0, 5, 1), "maze width must be 1 to 99 cells, not 0"),
        ((5, 100, 1), "maze height must be 1 to 99 cells, not 100"),
        ((5, 5.5, 1), "maze height must be a whole number of cells"),
    ],
)
def test_bad_size_is_refused_with_the_allowed_range(args, message):
    with pytest.raises(ValueError, match=message):
        generate(*args)


def test_negative_seed_is_refused():
    with pytest.raises(ValueError, match="seed must be a whole number 0 or more, not -7"):
        generate(4, 4, -7)


def test_unknown_style_and_exit_are_refused():
    with pytest.raises(ValueError, match="unknown maze style 'spiral'; use one of perfect, braid"):
        generate(4, 4, 1, "spiral")
    with pytest.raises(ValueError, match="unknown exit option 'corner'"):
        generate(4, 4, 1, exit="corner")


# -- bundled mazes -------------------------------------------------------------------------------


BUNDLED = sorted(MAZE_DIR.glob("*.txt"))


def test_the_lab_and_ranking_mazes_are_bundled():
    names = {p.name for p in BUNDLED}
    assert {
        "unity-default.txt",
        "erobotic.txt",
        "web.txt",
        "rank-wall-wins.txt",
        "rank-local-best-wins.txt",
        "trap-loop.txt",
    } <= names


@pytest.mark.parametrize("path", BUNDLED, ids=lambda p: p.name)
def test_bundled_maze_is_valid_and_described(path):
    maze = load_maze(path)
    assert maze.validate() == []
    assert maze.name.strip() and maze.name != path.stem
    assert len(maze.description.split()) >= 10
    assert maze.profile in PROFILES
    assert maze.width <= 25 or path.name == "unity-default.txt"


@pytest.mark.parametrize(
    "name",
    ["erobotic.txt", "web.txt", "rank-wall-wins.txt", "rank-local-best-wins.txt", "trap-loop.txt"],
)
def test_lab_mazes_have_one_block_corridors_and_an_exit(name):
    maze = load_maze(MAZE_DIR / name)
    assert maze.width <= 25 and maze.height <= 25
    assert maze.shortest_path_length() is not None
    for y in range(maze.height - 1):
        for x in range(maze.width - 1):
            square = [maze.is_wall(x + dx, y + dy) for dx in (0, 1) for dy in (0, 1)]
            assert any(square), f"{name}: a 2x2 open area at ({x}, {y})"


def test_erobotic_and_web_exits_are_openings_in_the_outer_wall():
    for name, profile in (("erobotic.txt", "erobotic"), ("web.txt", "web")):
        maze = load_maze(MAZE_DIR / name)
        assert maze.profile == profile
        ((x, y),) = maze.exits
        assert x in (0, maze.width - 1) or y in (0, maze.height - 1)


# -- command line ----------------------------------------------------------------------------------


def test_cli_generate_prints_the_maze_in_the_workbench_format(capsys):
    assert main(["maze", "generate", "--size", "16x16", "--seed", "7"]) == 0
    out = capsys.readouterr().out
    assert out.startswith("---\nname: perfect 16x16 seed 7\n")
    assert parse_maze(out).same_layout(generate(16, 16, 7))


def test_cli_generate_options_reach_the_generator(capsys):
    argv = ["maze", "generate", "--size", "6x4", "--seed", "3", "--style", "braid"]
    assert main([*argv, "--exit", "center"]) == 0
    maze = parse_maze(capsys.readouterr().out)
    assert maze.same_layout(generate(6, 4, 3, "braid", "center"))
    assert maze.name == "braid 6x4 seed 3"


def test_cli_generate_writes_a_file_that_checks_valid(tmp_path, capsys):
    out = tmp_path / "gen.txt"
    argv = ["maze", "generate", "--size", "9x7", "--seed", "2", "--exit", "none", "-o", str(out)]
    assert main(argv) == 0
    assert f"{out}: written, perfect 9x7 seed 2 (19x15 blocks)" in capsys.readouterr().out
    assert load_maze(out).same_layout(generate(9, 7, 2, exit="none"))
    assert main(["maze", "check", str(out)]) == 0
    assert list(tmp_path.iterdir()) == [out]


@pytest.mark.parametrize(
    ("size", "message"),
    [
        ("16by16", "'16by16' is not a size: give WIDTHxHEIGHT in cells, e.g. 16x16"),
        ("0x5", "maze width must be 1 to 99 cells, not 0"),
        ("5x100", "maze height must be 1 to 99 cells, not 100"),
        ("-3x5", "is not a size"),
    ],
)
def test_cli_generate_bad_size_exits_2_with_a_clear_message(size, message, capsys):
    with pytest.raises(SystemExit) as exc:
        main(["maze", "generate", f"--size={size}", "--seed", "7"])
    assert exc.value.code == 2
    err = capsys.readouterr().err
    assert "argument --size" in err and message in err


@pytest.mark.parametrize("seed", ["seven", "-7", "1.5"])
def test_cli_generate_bad_seed_exits_2_with_a_clear_message(seed, capsys):
    with pytest.raises(SystemExit) as exc:
        main(["maze", "generate", "--size", "4x4", f"--seed={seed}"])
    assert exc.value.code == 2
    err = capsys.readouterr().err
    assert f"argument --seed: '{seed}' is not a seed: give a whole number 0 or more" in err


def test_cli_generate_bad_style_or_missing_seed_exits_2(capsys):
    with pytest.raises(SystemExit) as exc:
        main(["maze", "generate", "--size", "4x4", "--seed", "1", "--style", "spiral"])
    assert exc.value.code == 2
    assert "invalid choice: 'spiral'" in capsys.readouterr().err
    with pytest.raises(SystemExit) as exc:
        main(["maze", "generate", "--size", "4x4"])
    assert exc.value.code == 2
    assert "--seed" in capsys.readouterr().err


def test_cli_generate_unwritable_output_exits_1(tmp_path, capsys):
    target = tmp_path / "missing" / "gen.txt"
    argv = ["maze", "generate", "--size", "4x4", "--seed", "1", "-o", str(target)]
    assert main(argv) == 1
    assert f"{target}: cannot write" in capsys.readouterr().err
    assert not target.exists()


def test_centre_exit_never_lands_on_the_start():
    maze = generate(2, 2, 3, exit="center")
    assert maze.start not in maze.exits and len(maze.exits) == 3
    with pytest.raises(ValueError, match="no centre cell apart from the start"):
        generate(1, 1, 0, exit="center")
