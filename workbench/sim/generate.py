"""Seeded maze generators: wall-edge mazes of W x H cells drawn as block grids.

A maze of ``width`` x ``height`` cells becomes a (2W+1) x (2H+1) block grid: cell ``(cx, cy)``
is the floor block ``(2cx+1, 2cy+1)``, the block between two neighbouring cells is wall or
floor (a passage), and the blocks at even/even positions (the posts) are always wall. The same
seed always gives the same maze, on every platform, because only ``random.Random(seed)`` is used.

Styles:

* ``perfect``: a randomized depth-first search (recursive backtracker, run with an explicit
  stack), so there is exactly one path between any two cells and every cell is reachable.
* ``braid``: a perfect maze whose dead ends are then opened up, each by knocking out one of its
  walls (a wall into another dead end when there is one). Loops appear and no dead end is left
  but the start cell when both sides are at least 3 cells; a cell whose only closed wall faces
  the start stays a dead end (in a maze 2 cells wide, the start's neighbour may), and a maze
  1 cell wide keeps its two ends (or its single cell), since those cells have nowhere else to
  open into.

Exits:

* ``boundary``: an opening in the outer wall beside the boundary cell farthest from the start.
* ``center``: the centre cell (odd sizes) or the 2 x 2 centre cells (even sizes), the
  micromouse goal; a side with an even number of cells contributes its two middle cells.
* ``none``: no exit; runs on the maze are free exploration.

The start is always the bottom-left cell, and it always has one open side, which the robot
faces: it starts in a corridor with a wall on either hand, as a micromouse does, so a wall
follower (right hand or left hand) starts on the outer wall. When the spanning tree opens the
corner both ways, its passage to the right is closed and the part of the maze cut off that way
is joined on again elsewhere; braiding never opens the start cell again.
"""

from __future__ import annotations

import random
from collections import deque
from dataclasses import replace

from .maze import FLOOR, MAX_SIZE, WALL, Cell, Maze, default_heading

STYLES = ("perfect", "braid")
EXITS = ("boundary", "center", "none")
MIN_CELLS = 1
MAX_CELLS = (MAX_SIZE - 1) // 2

#: cell step (dx, dy) per direction, y grows downwards
_STEPS: tuple[Cell, ...] = ((0, -1), (1, 0), (0, 1), (-1, 0))


def block_of(cell: Cell) -> Cell:
    """The floor block that draws cell ``(cx, cy)``."""
    return (2 * cell[0] + 1, 2 * cell[1] + 1)


def check_size(width: int, height: int) -> None:
    """Raise ``ValueError`` with a readable reason unless W x H cells can be generated."""
    for label, value in (("width", width), ("height", height)):
        if isinstance(value, bool) or not isinstance(value, int):
            raise ValueError(f"maze {label} must be a whole number of cells, not {value!r}")
        if not MIN_CELLS <= value <= MAX_CELLS:
            raise ValueError(
                f"maze {label} must be {MIN_CELLS} to {MAX_CELLS} cells, not {value} "
                f"(W x H cells make a (2W+1) x (2H+1) block grid, at most {MAX_SIZE} blocks a side)"
            )


def check_seed(seed: int) -> None:
    """Raise ``ValueError`` unless ``seed`` is a whole number 0 or more.

    ``random.Random`` treats ``-n`` like ``n``; refusing negative seeds keeps "different seed,
    different maze" true.
    """
    if isinstance(seed, bool) or not isinstance(seed, int) or seed < 0:
        raise ValueError(f"seed must be a whole number 0 or more, not {seed!r}")


def generate(
    width: int,
    height: int,
    seed: int,
    style: str = "perfect",
    exit: str = "boundary",
) -> Maze:
    """A ``width`` x ``height`` cell maze; the same arguments always give the same maze."""
    check_size(width, height)
    check_seed(seed)
    if style not in STYLES:
        raise ValueError(f"unknown maze style {style!r}; use one of {', '.join(STYLES)}")
    if exit not in EXITS:
        raise ValueError(f"unknown exit option {exit!r}; use one of {', '.join(EXITS)}")
    rng = random.Random(seed)
    start_cell = (0, height - 1)
    passages = _backtracker(width, height, rng)
    _start_in_corridor(width, height, start_cell, passages, rng)
    if style == "braid":
        _braid(width, height, start_cell, passages, rng)
    grid = [[WALL] * (2 * width + 1) for _ in range(2 * height + 1)]
    for cy in range(height):
        for cx in range(width):
            x, y = block_of((cx, cy))
            grid[y][x] = FLOOR
    for a, b in passages:
        grid[a[1] + b[1] + 1][a[0] + b[0] + 1] = FLOOR
    exits = _exits(width, height, start_cell, passages, exit)
    for x, y in exits:
        grid[y][x] = FLOOR
    start = block_of(start_cell)
    maze = Maze(rows=tuple("".join(row) for row in grid), start=start, exits=exits)
    exit_text = {
        "boundary": "the exit is an opening in the outer wall beside the edge cell farthest "
        "from the start",
        "center": "the exits are the centre cells (the micromouse goal)",
        "none": "there is no exit, so runs are free exploration",
    }[exit]
    style_text = {
        "perfect": "exactly one path joins any two cells",
        "braid": "dead ends are opened up, so corridors form loops"
        if width > 1 and height > 1
        else "a maze one cell wide has no wall to open, so its ends stay dead ends",
    }[style]
    return replace(
        maze,
        heading=default_heading(maze, start),
        name=f"{style} {width}x{height} seed {seed}",
        description=(
            f"Generated {style} maze of {width} x {height} cells "
            f"({2 * width + 1} x {2 * height + 1} blocks, seed {seed}): {style_text}; "
            f"the robot starts in the bottom-left cell; {exit_text}."
        ),
    )


def _neighbours(cell: Cell, width: int, height: int) -> list[Cell]:
    cx, cy = cell
    return [
        (cx + dx, cy + dy) for dx, dy in _STEPS if 0 <= cx + dx < width and 0 <= cy + dy < height
    ]


def _edge(a: Cell, b: Cell) -> tuple[Cell, Cell]:
    return (a, b) if a <= b else (b, a)


def _backtracker(width: int, height: int, rng: random.Random) -> set[tuple[Cell, Cell]]:
    """The open passages of a spanning tree over all cells, as sorted cell pairs."""
    start = (rng.randrange(width), rng.randrange(height))
    visited = {start}
    stack = [start]
    passages: set[tuple[Cell, Cell]] = set()
    while stack:
        cell = stack[-1]
        fresh = [n for n in _neighbours(cell, width, height) if n not in visited]
        if not fresh:
            stack.pop()
            continue
        nxt = rng.choice(fresh)
        passages.add(_edge(cell, nxt))
        visited.add(nxt)
        stack.append(nxt)
    return passages


def _degree(cell: Cell, passages: set[tuple[Cell, Cell]], width: int, height: int) -> int:
    return sum(_edge(cell, n) in passages for n in _neighbours(cell, width, height))


def _start_in_corridor(
    width: int,
    height: int,
    start: Cell,
    passages: set[tuple[Cell, Cell]],
    rng: random.Random,
) -> None:
    """Leave the start cell of a spanning tree one opening, keeping every cell reachable.

    A corner cell open both up and to the right has one of those sides open beside a robot
    facing the other, and a wall follower takes that side for a turning before it has started.
    With one opening the robot starts in a corridor, a wall on either hand (the micromouse
    start cell). The passage to the right is closed; the cells it cut off are joined to the
    rest again through a wall chosen at random among those between the two parts.
    """
    right = (start[0] + 1, start[1])
    if _degree(start, passages, width, height) < 2 or _edge(start, right) not in passages:
        return
    passages.discard(_edge(start, right))
    cut_off = set(_cell_distances(right, passages, width, height))
    bridges = sorted(
        _edge(cell, n)
        for cell in cut_off
        for n in _neighbours(cell, width, height)
        if n not in cut_off and n != start
    )
    passages.add(rng.choice(bridges))


def _braid(
    width: int,
    height: int,
    start: Cell,
    passages: set[tuple[Cell, Cell]],
    rng: random.Random,
) -> None:
    """Open one more wall of every dead end but the start, preferring a wall into another
    dead end; no wall of the start cell is opened."""
    cells = [(cx, cy) for cy in range(height) for cx in range(width) if (cx, cy) != start]
    rng.shuffle(cells)
    for cell in cells:
        if _degree(cell, passages, width, height) != 1:
            continue
        closed = [
            n
            for n in _neighbours(cell, width, height)
            if _edge(cell, n) not in passages and n != start
        ]
        if not closed:
            continue
        dead = [n for n in closed if _degree(n, passages, width, height) == 1]
        passages.add(_edge(cell, rng.choice(dead or closed)))


def _cell_distances(start: Cell, passages: set[tuple[Cell, Cell]], width: int, height: int):
    dist = {start: 0}
    queue = deque([start])
    while queue:
        cell = queue.popleft()
        for n in _neighbours(cell, width, height):
            if n not in dist and _edge(cell, n) in passages:
                dist[n] = dist[cell] + 1
                queue.append(n)
    return dist


def _exits(
    width: int,
    height: int,
    start: Cell,
    passages: set[tuple[Cell, Cell]],
    option: str,
) -> tuple[Cell, ...]:
    if option == "none":
        return ()
    if option == "center":
        cols = [width // 2] if width % 2 else [width // 2 - 1, width // 2]
        rows = [height // 2] if height % 2 else [height // 2 - 1, height // 2]
        centre = tuple(block_of((cx, cy)) for cy in rows for cx in cols if (cx, cy) != start)
        if not centre:
            raise ValueError(
                f"a {width}x{height} maze has no centre cell apart from the start; "
                "use a larger size or --exit boundary"
            )
        return centre
    dist = _cell_distances(start, passages, width, height)
    edge_cells = [
        (cx, cy)
        for cy in range(height)
        for cx in range(width)
        if cx in (0, width - 1) or cy in (0, height - 1)
    ]
    far = max(edge_cells, key=lambda c: (dist[c], -c[1], c[0]))
    bx, by = block_of(far)
    sx, sy = block_of(start)
    openings = []
    if far[1] == 0:
        openings.append((bx, 0))
    if far[0] == width - 1:
        openings.append((2 * width, by))
    if far[1] == height - 1:
        openings.append((bx, 2 * height))
    if far[0] == 0:
        openings.append((0, by))
    return (max(openings, key=lambda b: abs(b[0] - sx) + abs(b[1] - sy)),)
