"""The classic binary ``.maz`` micromouse maze: 256 bytes, one per cell of a 16x16 maze.

Byte ``16 * x + y`` holds the walls of cell ``(x, y)``, y counted from the bottom, as bits
``N=1 E=2 S=4 W=8`` (the upper four bits are not walls and are ignored). The mouse starts in
cell (0, 0) facing north; the goal is the four centre cells.

Some tools write the bytes row by row from the top-left instead (byte ``16 * row + col``, row 0
the top row). The layout is recognised by which reading makes every internal wall agree on
both of its sides; when both do, the classic layout wins.
"""

from __future__ import annotations

from collections.abc import Callable

from .maze import Cell, Maze, MazeError, Problem
from .wallmaze import WallMaze, from_blocks, wall_problems

SIZE = 16
GOALS: tuple[Cell, ...] = ((7, 7), (7, 8), (8, 7), (8, 8))


def _classic_index(x: int, y: int) -> int:
    return SIZE * x + y


def _row_major_index(x: int, y: int) -> int:
    return SIZE * (SIZE - 1 - y) + x


def _read(data: bytes, index: Callable[[int, int], int], source: str) -> WallMaze:
    walls = tuple(data[index(x, y)] & 0x0F for y in range(SIZE) for x in range(SIZE))
    return WallMaze(SIZE, SIZE, walls, start=(0, 0), heading="up", goals=GOALS, source=source)


def parse_maz(data: bytes, source: str = "<maze>") -> WallMaze:
    """Read a 256-byte ``.maz`` file in whichever layout is consistent (classic preferred)."""
    if len(data) != SIZE * SIZE:
        raise MazeError(
            [
                Problem(
                    f"a .maz file is {SIZE * SIZE} bytes (one per cell of a 16x16 maze), "
                    f"this one is {len(data)} bytes",
                    "check that it is a binary .maz maze, or pass --from with its real format",
                    source,
                )
            ]
        )
    classic = _read(data, _classic_index, source)
    disagree_classic = len(wall_problems(classic))
    if not disagree_classic:
        return classic
    row_major = _read(data, _row_major_index, source)
    disagree_rows = len(wall_problems(row_major))
    if not disagree_rows:
        return row_major
    raise MazeError(
        [
            Problem(
                "the walls do not fit together in either layout; internal walls whose two "
                f"sides disagree: {disagree_classic} when read column by column from the "
                f"bottom-left (classic .maz), {disagree_rows} when read row by row from the "
                "top-left",
                "the file is damaged or is not a .maz maze",
                source,
            )
        ]
    )


def format_maz(maze: Maze) -> bytes:
    """The classic ``.maz`` bytes of a 16x16-cell maze that starts and ends as .maz requires."""
    wm = from_blocks(maze)
    if (wm.width, wm.height) != (SIZE, SIZE):
        raise MazeError(
            [
                maze.problem(
                    f"the maze is {wm.width}x{wm.height} cells; a .maz file holds exactly "
                    f"{SIZE}x{SIZE}",
                    "write micromouse text instead (--to micromouse)",
                )
            ]
        )
    problems = []
    if wm.start != (0, 0) or wm.heading != "up":
        where = f"cell {wm.start} facing {wm.heading}" if wm.start else "missing"
        problems.append(
            maze.problem(
                f"the start is {where}; a .maz maze always starts in cell (0, 0) facing up",
                "move the start to the bottom-left cell facing up, or write micromouse text",
            )
        )
    if wm.goals != GOALS:
        goals = ", ".join(str(g) for g in wm.goals) or "none"
        problems.append(
            maze.problem(
                f"the goal cells are {goals}; a .maz maze always has its goal in the four "
                "centre cells (7, 7), (7, 8), (8, 7), (8, 8)",
                "mark exactly the four centre cells as exits, or write micromouse text",
            )
        )
    if problems:
        raise MazeError(problems)
    data = bytearray(SIZE * SIZE)
    for y in range(SIZE):
        for x in range(SIZE):
            data[_classic_index(x, y)] = wm.bits(x, y)
    return bytes(data)
