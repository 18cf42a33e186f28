"""Wall-edge mazes (the micromouse model) and their conversion to and from block mazes.

A ``WallMaze`` is ``width`` x ``height`` cells; cell ``(x, y)`` has ``y = 0`` at the BOTTOM
row. Each cell holds wall bits ``N=1 E=2 S=4 W=8``. As blocks it becomes a
``(2W+1) x (2H+1)`` grid: cell ``(x, y)`` is block ``(2x+1, 2(H-1-y)+1)``, the blocks between
two cells are wall or floor, and the corner posts (even, even) are always wall.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

from .maze import FLOOR, MAX_SIZE, WALL, Cell, Maze, MazeError, Problem, default_heading

N, E, S, W = 1, 2, 4, 8
#: side name -> (wall bit, step to the neighbouring cell with y growing upwards)
SIDES: dict[str, tuple[int, Cell]] = {
    "north": (N, (0, 1)),
    "east": (E, (1, 0)),
    "south": (S, (0, -1)),
    "west": (W, (-1, 0)),
}
OPPOSITE = {"north": "south", "east": "west", "south": "north", "west": "east"}
#: the most cells along one side that still fit in the block size limit
MAX_CELLS = (MAX_SIZE - 1) // 2

#: (cell, side) -> (line, col) in the file the wall maze came from, for messages
Where = Callable[[Cell, str], tuple[int, int]]


@dataclass(frozen=True)
class WallMaze:
    width: int
    height: int
    #: wall bits of cell (x, y) at index ``y * width + x``
    walls: tuple[int, ...]
    start: Cell | None = (0, 0)
    #: a block heading name (up/right/down/left); None picks the default on conversion
    heading: str | None = None
    goals: tuple[Cell, ...] = ()
    name: str = ""
    source: str = "<maze>"

    def __post_init__(self) -> None:
        if self.width < 1 or self.height < 1:
            raise ValueError("a wall maze needs at least one cell")
        if len(self.walls) != self.width * self.height:
            raise ValueError(f"expected {self.width * self.height} cells, got {len(self.walls)}")
        cells = [self.start] if self.start is not None else []
        for cell in [*cells, *self.goals]:
            if not self.in_bounds(*cell):
                raise ValueError(f"cell {cell} is outside the {self.width}x{self.height} maze")
        object.__setattr__(self, "goals", tuple(sorted(set(self.goals))))

    def in_bounds(self, x: int, y: int) -> bool:
        return 0 <= x < self.width and 0 <= y < self.height

    def bits(self, x: int, y: int) -> int:
        return self.walls[y * self.width + x]

    def has_wall(self, cell: Cell, side: str) -> bool:
        return bool(self.bits(*cell) & SIDES[side][0])


def wall_problems(wm: WallMaze, where: Where | None = None) -> list[Problem]:
    """Every internal wall whose two sides disagree (nothing is fixed silently)."""
    problems = []
    for y in range(wm.height):
        for x in range(wm.width):
            for side in ("east", "north"):
                dx, dy = SIDES[side][1]
                other = (x + dx, y + dy)
                if not wm.in_bounds(*other):
                    continue
                here = wm.has_wall((x, y), side)
                there = wm.has_wall(other, OPPOSITE[side])
                if here == there:
                    continue
                walled, open_ = ((x, y), other) if here else (other, (x, y))
                walled_side = side if here else OPPOSITE[side]
                line, col = where(walled, walled_side) if where else (0, 0)
                problems.append(
                    Problem(
                        f"cell {walled} has a wall on its {walled_side} side but cell {open_} "
                        f"has none on its {OPPOSITE[walled_side]} side",
                        "give both cells the wall or remove it from both",
                        wm.source,
                        line,
                        col,
                    )
                )
    return problems


def block_of(wm: WallMaze, cell: Cell) -> Cell:
    return (2 * cell[0] + 1, 2 * (wm.height - 1 - cell[1]) + 1)


#: what a wall maze's source gains when it is turned into blocks (the file is still the source)
AS_BLOCKS = " (as blocks)"


def source_file(source: str) -> str:
    """The file a maze's ``source`` names: a wall maze turned into blocks says so after it."""
    return source.removesuffix(AS_BLOCKS)


def to_blocks(wm: WallMaze) -> Maze:
    """The block maze of a consistent wall maze; goal cells become exits."""
    problems = wall_problems(wm)
    if problems:
        raise MazeError(problems)
    grid = [[WALL] * (2 * wm.width + 1) for _ in range(2 * wm.height + 1)]
    for y in range(wm.height):
        for x in range(wm.width):
            bx, by = block_of(wm, (x, y))
            grid[by][bx] = FLOOR
            for bit, (dx, dy) in SIDES.values():
                if not wm.bits(x, y) & bit:
                    grid[by - dy][bx + dx] = FLOOR
    maze = Maze(
        rows=tuple("".join(row) for row in grid),
        exits=tuple(block_of(wm, g) for g in wm.goals),
        name=wm.name,
        source=f"{wm.source}{AS_BLOCKS}",
    )
    if wm.start is None:
        return maze
    start = block_of(wm, wm.start)
    return maze.with_start(*start, wm.heading or default_heading(maze, start))


def _fit_problems(maze: Maze) -> list[Problem]:
    w, h = maze.width, maze.height
    if w < 3 or h < 3 or w % 2 == 0 or h % 2 == 0:
        return [
            maze.problem(
                f"the maze is {w}x{h} blocks; a micromouse maze has an odd width and height "
                "(2 x cells + 1) of at least 3",
                "add or remove one row or column of blocks",
            )
        ]
    problems = []
    for y in range(h):
        for x in range(w):
            if x % 2 == 0 and y % 2 == 0 and not maze.is_wall(x, y):
                problems.append(
                    maze.problem(
                        "floor at a corner post between micromouse cells",
                        "make it a # wall: every second block of every second row is a post",
                        (x, y),
                    )
                )
            elif x % 2 == 1 and y % 2 == 1 and maze.is_wall(x, y):
                problems.append(
                    maze.problem(
                        "wall block inside a micromouse cell",
                        "make it . floor: cells are the blocks between the posts",
                        (x, y),
                    )
                )
    if maze.start is not None and (maze.start[0] % 2 == 0 or maze.start[1] % 2 == 0):
        problems.append(
            maze.problem(
                "start is not on a micromouse cell",
                "move it onto a cell block, between four corner posts",
                maze.start,
            )
        )
    for x, y in maze.exits:
        if x in (0, w - 1) or y in (0, h - 1):
            problems.append(
                maze.problem(
                    "exit on the outer boundary cannot be written as a micromouse goal cell",
                    "move the exit inside the maze, onto a cell block",
                    (x, y),
                )
            )
        elif x % 2 == 0 or y % 2 == 0:
            problems.append(
                maze.problem(
                    "exit between two cells cannot be written as a micromouse goal cell",
                    "move the exit onto a cell block, between four corner posts",
                    (x, y),
                )
            )
    return problems


def from_blocks(maze: Maze) -> WallMaze:
    """The wall maze of a block maze on the micromouse grid; MazeError says why it is not."""
    problems = _fit_problems(maze)
    if problems:
        raise MazeError(problems)
    width, height = (maze.width - 1) // 2, (maze.height - 1) // 2

    def cell_of(block: Cell) -> Cell:
        return ((block[0] - 1) // 2, height - 1 - (block[1] - 1) // 2)

    walls = []
    for y in range(height):
        for x in range(width):
            bx, by = 2 * x + 1, 2 * (height - 1 - y) + 1
            bits = 0
            for bit, (dx, dy) in SIDES.values():
                if maze.is_wall(bx + dx, by - dy):
                    bits |= bit
            walls.append(bits)
    return WallMaze(
        width=width,
        height=height,
        walls=tuple(walls),
        start=cell_of(maze.start) if maze.start is not None else None,
        heading=maze.heading,
        goals=tuple(cell_of(e) for e in maze.exits),
        name=maze.name,
        source=source_file(maze.source),
    )
