"""Micromouse text mazes: micromouseonline text, the mms "map" and "num" formats, and a writer.

micromouseonline text (the format of the micromouseonline/mazefiles collection)::

    o---o---o
    | G     |
    o   o---o
    | S     |
    o---o---o

Post lines and cell lines alternate; every cell is three characters between ``o`` posts, so a
line is 4 x W + 1 characters long. Any non-space at the middle of a wall segment is a wall.
``S`` marks the start cell, ``G`` the goal cells (they become exits).

The mms "map" format is the same picture with ``+`` posts. The mms simulator reads cells three
characters wide; its older versions took each column's width from the posts of the first line,
and so does this reader. ``S`` and ``G`` are accepted there too.

The mms "num" format has one line ``x y N E S W`` per cell: walls 0 or 1, y from the bottom.

Without an ``S`` the start is the bottom-left cell (0, 0), the micromouse convention, and a file
without ``G`` has no exits: a free-exploration maze.
"""

from __future__ import annotations

import itertools
import re
from dataclasses import dataclass, field

from workbench.files.bounded import MAZE_LIMITS, BoundedFileError, check_text, digits_problem

from .maze import Cell, Maze, MazeError, Problem
from .wallmaze import MAX_CELLS, E, N, S, W, WallMaze, from_blocks, wall_problems

CELL_HINT = "a cell holds spaces, S for the start or G for a goal"


def _corner(i: int, r: int, width: int, height: int) -> str:
    """Post ``i`` (0 = left) on post line ``r`` (0 = top) named by a cell it touches."""
    cy = height - r
    x, y = min(i, width - 1), min(cy, height - 1)
    return (
        f"the {'south' if cy < height else 'north'}-{'west' if i < width else 'east'} "
        f"corner of cell ({x}, {y})"
    )


def _first_line_posts(first: str, post: str, fixed: bool, source: str, line: int) -> list[int]:
    """Columns of the posts, from the first line; raise MazeError when its shape is wrong."""

    def fail(message: str, hint: str, col: int) -> MazeError:
        return MazeError([Problem(message, hint, source, line, col)])

    if fixed:
        size = len(first.rstrip(" "))
        if size % 4 != 1 and len(first) % 4 == 1:
            size = len(first)
        if size < 5 or (size - 1) % 4:
            raise fail(
                f"the first line is {size} characters long; a micromouse maze line is "
                f"4 x cells + 1 characters ({post}---{post} for one cell)",
                "make every cell three characters wide between posts",
                size,
            )
        return list(range(0, size, 4))
    if not first.startswith(post):
        raise fail(f"the first line must start with a {post!r} post", "draw the top wall first", 1)
    first = first.rstrip(" ")
    if not first.endswith(post):
        raise fail(
            f"the first line must end with a {post!r} post",
            "close the top wall with a post",
            len(first),
        )
    cols = [i for i, ch in enumerate(first) if ch == post]
    if len(cols) < 2:
        raise fail("the first line needs at least two posts", "draw one cell at least", 1)
    for a, b in itertools.pairwise(cols):
        if b == a + 1:
            raise fail(
                "two posts with no cell between them",
                "put the wall characters between posts",
                b + 1,
            )
    return cols


@dataclass
class _Picture:
    """Walls and marks read so far from a post-and-wall picture, and what was wrong with it."""

    source: str
    post: str
    cols: list[int]
    height: int
    hwall: list[list[bool]] = field(default_factory=list)
    vwall: list[list[bool]] = field(default_factory=list)
    starts: list[tuple[Cell, int, int]] = field(default_factory=list)
    goals: set[Cell] = field(default_factory=set)
    problems: list[Problem] = field(default_factory=list)

    def __post_init__(self) -> None:
        self.hwall = [[False] * self.width for _ in range(self.height + 1)]
        self.vwall = [[False] * (self.width + 1) for _ in range(self.height)]

    @property
    def width(self) -> int:
        return len(self.cols) - 1

    def problem(self, message: str, hint: str, line: int, col: int) -> None:
        self.problems.append(Problem(message, hint, self.source, line, col))

    def segments(self, line: str) -> list[tuple[int, str]]:
        return [(a + 1, line[a + 1 : b]) for a, b in itertools.pairwise(self.cols)]

    def read_post_line(self, r: int, ln: int, line: str) -> None:
        """Post line ``r`` (0 = top): the north walls of text row ``r``."""
        for i, c in enumerate(self.cols):
            if line[c] != self.post:
                found = "missing post" if line[c] == " " else f"{line[c]!r} instead of a post"
                self.problem(
                    f"{found} at {_corner(i, r, self.width, self.height)}",
                    f"put {self.post!r} at every corner, also between open cells",
                    ln,
                    c + 1,
                )
        for j, (a, segment) in enumerate(self.segments(line)):
            middle = (len(segment) - 1) // 2
            self.hwall[r][j] = segment[middle] != " "
            if segment[middle] == " " and segment.strip():
                self.problem(
                    f"wall segment {segment!r} has nothing at its middle",
                    f"write {'-' * len(segment)!r} for a wall or only spaces for none",
                    ln,
                    a + len(segment) - len(segment.lstrip()) + 1,
                )

    def read_cell_line(self, r: int, ln: int, line: str) -> None:
        """Cell line ``r`` (0 = top): the west and east walls and the S/G marks of text row r."""
        for i, c in enumerate(self.cols):
            self.vwall[r][i] = line[c] != " "
        for j, (a, segment) in enumerate(self.segments(line)):
            cell = (j, self.height - 1 - r)
            for off, ch in enumerate(segment):
                if ch == "S" and all(s[0] != cell for s in self.starts):
                    self.starts.append((cell, ln, a + off + 1))
                elif ch == "G":
                    self.goals.add(cell)
                elif ch not in " S":
                    self.problem(
                        f"unknown character {ch!r} in cell {cell}", CELL_HINT, ln, a + off + 1
                    )

    def wall_maze(self) -> WallMaze:
        if len(self.starts) > 1:
            for cell, ln, col in self.starts:
                self.problem(
                    f"cell {cell} is one of {len(self.starts)} start cells", "keep one S", ln, col
                )
        if self.problems:
            raise MazeError(self.problems)
        walls = []
        for y in range(self.height):
            r = self.height - 1 - y
            for x in range(self.width):
                hw, vw = self.hwall, self.vwall[r]
                walls.append(N * hw[r][x] | S * hw[r + 1][x] | W * vw[x] | E * vw[x + 1])
        return WallMaze(
            width=self.width,
            height=self.height,
            walls=tuple(walls),
            start=self.starts[0][0] if self.starts else (0, 0),
            goals=tuple(self.goals),
            source=self.source,
        )


def _checked_lines(text: str, source: str) -> list[str]:
    """The lines of ``text`` once its size and characters are known to be fine."""
    try:
        return check_text(text, source, MAZE_LIMITS).splitlines()
    except BoundedFileError as exc:
        raise MazeError.refused(exc) from None


def _too_large(what: str, count: int, source: str, line: int, col: int) -> MazeError:
    return MazeError(
        [
            Problem(
                f"the maze has {count:,} {what}; a maze has at most {MAX_CELLS} cells a side",
                "split the maze",
                source,
                line,
                col,
            )
        ]
    )


def _parse_posts(text: str, source: str, post: str, fixed: bool) -> WallMaze:
    raw = _checked_lines(text, source)
    top = 0
    while top < len(raw) and not raw[top].strip():
        top += 1
    end = len(raw)
    while end > top and not raw[end - 1].strip():
        end -= 1
    lines = raw[top:end]
    if not lines:
        raise MazeError(
            [Problem("the file holds no maze", f"draw the maze with {post} posts", source)]
        )
    cols = _first_line_posts(lines[0], post, fixed, source, top + 1)
    if len(cols) - 1 > MAX_CELLS:
        raise _too_large(
            "columns of cells", len(cols) - 1, source, top + 1, cols[MAX_CELLS + 1] + 1
        )
    if len(lines) > 2 * MAX_CELLS + 1:
        rows = (len(lines) - 1) // 2
        raise _too_large("rows of cells", rows, source, top + 2 * MAX_CELLS + 2, 1)
    if len(lines) < 3 or len(lines) % 2 == 0:
        raise MazeError(
            [
                Problem(
                    f"the maze has {len(lines)} lines; post lines and cell lines alternate, "
                    "starting and ending with a post line, so it needs an odd number (at least 3)",
                    "add or remove a line so that there are 2 x rows + 1",
                    source,
                    top + len(lines),
                    1,
                )
            ]
        )
    picture = _Picture(source, post, cols, (len(lines) - 1) // 2)
    length = cols[-1] + 1
    for k, line in enumerate(lines):
        ln = top + k + 1
        size = len(line.rstrip(" ")) if len(line) > length else len(line)
        if size != length:
            long = size > length
            picture.problem(
                f"line is {size} characters long, {'longer' if long else 'shorter'} than "
                f"the first line ({length})",
                "every line of the maze has the same length: "
                + ("remove the extra characters" if long else "pad it with spaces"),
                ln,
                length + 1 if long else size + 1,
            )
        elif k % 2 == 0:
            picture.read_post_line(k // 2, ln, line)
        else:
            picture.read_cell_line(k // 2, ln, line)
    return picture.wall_maze()


def parse_micromouse(text: str, source: str = "<maze>") -> WallMaze:
    """micromouseonline text (``o`` posts, three-character cells)."""
    return _parse_posts(text, source, "o", fixed=True)


def parse_mms_map(text: str, source: str = "<maze>") -> WallMaze:
    """The mms "map" picture (``+`` posts; column widths from the first line)."""
    return _parse_posts(text, source, "+", fixed=False)


NUM_FIELDS = ("x", "y", "N", "E", "S", "W")
NUM_HINT = "write one cell per line: its x, y and 0/1 for the north, east, south, west walls"


def _num_values(raw: str, ln: int, source: str, problems: list[Problem]) -> list[int] | None:
    """The six numbers of one num line, or None (with the reasons added to ``problems``)."""
    tokens = [(m.group(), m.start() + 1) for m in re.finditer(r"\S+", raw)]
    if len(tokens) != 6:
        found = f"expected six numbers 'x y N E S W', found {len(tokens)} fields"
        problems.append(Problem(found, NUM_HINT, source, ln, 1))
        return None
    values, ok = [], True
    for (tok, col), name in zip(tokens, NUM_FIELDS, strict=True):
        long = digits_problem(tok)
        value = int(tok) if re.fullmatch(r"[0-9]+", tok) and long is None else None
        if long is not None:
            wrong = (f"{name} is {long}", "check the coordinate")
        elif value is None:
            wrong = (f"{name} is {tok!r}, not a whole number", "use digits only")
        elif name in "xy" and value >= MAX_CELLS:
            wrong = (
                f"{name} is {value}; a maze has at most {MAX_CELLS} cells a side",
                "check the coordinate",
            )
        elif name not in "xy" and value not in (0, 1):
            wrong = (f"{name} wall is {value}; walls are 0 (open) or 1 (wall)", "write 0 or 1")
        else:
            values.append(value)
            continue
        problems.append(Problem(*wrong, source, ln, col))
        ok = False
    return values if ok else None


def parse_mms_num(text: str, source: str = "<maze>") -> WallMaze:
    """The mms "num" format: one ``x y N E S W`` line per cell, origin bottom-left."""
    problems: list[Problem] = []
    cells: dict[Cell, tuple[int, int]] = {}
    for ln, raw in enumerate(_checked_lines(text, source), start=1):
        values = _num_values(raw, ln, source, problems) if raw.strip() else None
        if values is None:
            continue
        x, y, n, e, s, w = values
        if (x, y) in cells:
            problems.append(
                Problem(
                    f"cell ({x}, {y}) is listed again; it was first on line {cells[(x, y)][0]}",
                    "keep one line per cell",
                    source,
                    ln,
                    1,
                )
            )
            continue
        cells[(x, y)] = (ln, N * n | E * e | S * s | W * w)
    if not cells and not problems:
        problems.append(Problem("the file lists no cells", "write 'x y N E S W' lines", source))
    width = max((x + 1 for x, _ in cells), default=0)
    height = max((y + 1 for _, y in cells), default=0)
    for y in range(height):
        for x in range(width):
            if (x, y) not in cells:
                problems.append(
                    Problem(
                        f"cell ({x}, {y}) is missing from the {width}x{height} maze",
                        f"add a line '{x} {y} N E S W' for it",
                        source,
                    )
                )
    if problems:
        raise MazeError(problems)
    wm = WallMaze(
        width=width,
        height=height,
        walls=tuple(cells[(x, y)][1] for y in range(height) for x in range(width)),
        source=source,
    )
    problems = wall_problems(wm, lambda cell, _side: (cells[cell][0], 1))
    if problems:
        raise MazeError(problems)
    return wm


def format_micromouse(maze: Maze) -> str:
    """micromouseonline text of a maze laid out on the micromouse grid (see ``from_blocks``)."""
    wm = from_blocks(maze)
    marks = {(True, False): " S ", (False, True): " G ", (True, True): "S G"}

    def post_line(y: int, side: str) -> str:
        walls = ("---" if wm.has_wall((x, y), side) else "   " for x in range(wm.width))
        return "o" + "".join(w + "o" for w in walls)

    out = [post_line(wm.height - 1, "north")]
    for y in range(wm.height - 1, -1, -1):
        line = "|" if wm.has_wall((0, y), "west") else " "
        for x in range(wm.width):
            line += marks.get(((x, y) == wm.start, (x, y) in wm.goals), "   ")
            line += "|" if wm.has_wall((x, y), "east") else " "
        out.append(line)
        out.append(post_line(y, "south"))
    return "\n".join(out) + "\n"
