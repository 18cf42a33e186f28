"""The block maze: a rectangular grid of wall and floor blocks, one start pose, exit cells.

Coordinates are ``(x, y)`` = (column, row), 0-based, row 0 at the top. Headings are the
names in :data:`HEADINGS`. A ``Maze`` is immutable; editing returns a new maze, which makes
undo/redo and comparisons trivial.
"""

from __future__ import annotations

import hashlib
from collections import deque
from collections.abc import Iterable, Iterator
from dataclasses import dataclass, field, replace

from workbench.files.bounded import BoundedFileError, capped, more_problems
from workbench.files.problems import Problem

Cell = tuple[int, int]

WALL = "#"
FLOOR = "."
MAX_SIZE = 200

#: heading name -> unit step (dx, dy) in grid coordinates (y grows downwards)
HEADINGS: dict[str, Cell] = {"up": (0, -1), "right": (1, 0), "down": (0, 1), "left": (-1, 0)}
PROFILES = ("unity", "web", "erobotic")


def problem_fields(problem: Problem) -> dict[str, object]:
    """A maze problem as ``workbench maze check --json`` writes it (a place not known: null)."""
    return {
        "source": problem.source,
        "line": problem.line or None,
        "col": problem.column or None,
        "message": problem.message,
        "hint": problem.hint,
    }


class MazeError(ValueError):
    """A maze could not be read; carries every problem found, not just the first (a long list
    is cut after :data:`~workbench.files.bounded.MAX_PROBLEMS`, saying how many more)."""

    def __init__(self, problems: list[Problem]):
        self.problems = cap_problems(problems)
        super().__init__("\n".join(str(p) for p in self.problems))

    @classmethod
    def refused(cls, exc: BoundedFileError, hint: str = "") -> MazeError:
        """The error of a file refused by the bounded reader, in maze-problem form."""
        return cls(
            [Problem(exc.message, hint or exc.hint, exc.path, exc.line or 0, exc.column or 0)]
        )


def cap_problems(problems: list[Problem]) -> list[Problem]:
    """At most :data:`~workbench.files.bounded.MAX_PROBLEMS` problems, then one saying how
    many more there are."""
    source = problems[0].source if problems else "<maze>"
    return capped(
        list(problems),
        lambda n: Problem(more_problems(n), "fix the problems above and check again", source),
    )


@dataclass(frozen=True)
class Maze:
    rows: tuple[str, ...]
    start: Cell | None = None
    heading: str = "right"
    exits: tuple[Cell, ...] = ()
    name: str = ""
    description: str = ""
    profile: str | None = None
    cell: float | None = None
    # where the grid came from, for messages; not part of the maze's identity
    source: str = field(default="<maze>", compare=False)
    body_line: int = field(default=1, compare=False)

    def __post_init__(self) -> None:
        widths = {len(r) for r in self.rows}
        if len(widths) > 1:
            raise ValueError("maze rows must all have the same width")
        bad = {c for r in self.rows for c in r} - {WALL, FLOOR}
        if bad:
            raise ValueError(f"maze rows may only hold '#' and '.', not {sorted(bad)}")
        if self.heading not in HEADINGS:
            raise ValueError(f"unknown heading {self.heading!r}; use one of {list(HEADINGS)}")
        object.__setattr__(
            self, "exits", tuple(sorted(set(self.exits), key=lambda c: (c[1], c[0])))
        )

    # -- shape -------------------------------------------------------------------------
    @property
    def width(self) -> int:
        return len(self.rows[0]) if self.rows else 0

    @property
    def height(self) -> int:
        return len(self.rows)

    def in_bounds(self, x: int, y: int) -> bool:
        return 0 <= x < self.width and 0 <= y < self.height

    def is_wall(self, x: int, y: int) -> bool:
        """Outside the grid counts as wall for movement, not for the boundary check."""
        return not self.in_bounds(x, y) or self.rows[y][x] == WALL

    def is_exit(self, x: int, y: int) -> bool:
        return (x, y) in self.exits

    def floor_neighbours(self, cell: Cell) -> Iterator[Cell]:
        x, y = cell
        for dx, dy in HEADINGS.values():
            if not self.is_wall(x + dx, y + dy):
                yield (x + dx, y + dy)

    # -- editing (each returns a new maze) -----------------------------------------------
    def with_block(self, x: int, y: int, wall: bool) -> Maze:
        row = self.rows[y]
        new_row = row[:x] + (WALL if wall else FLOOR) + row[x + 1 :]
        rows = (*self.rows[:y], new_row, *self.rows[y + 1 :])
        exits = tuple(e for e in self.exits if not (wall and e == (x, y)))
        return replace(self, rows=rows, exits=exits)

    def with_start(self, x: int, y: int, heading: str | None = None) -> Maze:
        return replace(self, start=(x, y), heading=heading or self.heading)

    def mirrored(self) -> Maze:
        """The maze seen in a mirror, left and right swapped (start, heading and exits too).

        A left-hand rule on a maze does what the right-hand rule does on its mirror image.
        """
        last = self.width - 1
        flip = {"left": "right", "right": "left"}
        return replace(
            self,
            rows=tuple(row[::-1] for row in self.rows),
            start=None if self.start is None else (last - self.start[0], self.start[1]),
            heading=flip.get(self.heading, self.heading),
            exits=tuple((last - x, y) for x, y in self.exits),
            name=f"{self.name} (mirrored)" if self.name else "",
        )

    def with_exit(self, x: int, y: int, present: bool = True) -> Maze:
        exits = set(self.exits)
        if present:
            exits.add((x, y))
        else:
            exits.discard((x, y))
        return replace(self, exits=tuple(exits))

    # -- questions ------------------------------------------------------------------------
    def distances_from(self, origin: Cell) -> dict[Cell, int]:
        """BFS step counts over floor blocks (4-neighbour) from ``origin``."""
        if self.is_wall(*origin):
            return {}
        dist = {origin: 0}
        queue = deque([origin])
        while queue:
            cell = queue.popleft()
            for nxt in self.floor_neighbours(cell):
                if nxt not in dist:
                    dist[nxt] = dist[cell] + 1
                    queue.append(nxt)
        return dist

    def shortest_path_length(self) -> int | None:
        """Blocks to walk from the start to the nearest exit; None without a reachable exit."""
        if self.start is None or not self.exits:
            return None
        dist = self.distances_from(self.start)
        reached = [dist[e] for e in self.exits if e in dist]
        return min(reached) if reached else None

    def digest(self) -> str:
        """A short content hash of the layout (grid, start, heading, exits)."""
        h = hashlib.sha256()
        h.update("\n".join(self.rows).encode())
        h.update(repr((self.start, self.heading, self.exits)).encode())
        return h.hexdigest()[:16]

    def same_layout(self, other: Maze) -> bool:
        return (self.rows, self.start, self.heading, self.exits) == (
            other.rows,
            other.start,
            other.heading,
            other.exits,
        )

    # -- validation -----------------------------------------------------------------------
    def problem(self, message: str, hint: str, cell: Cell | None = None) -> Problem:
        if cell is None:
            return Problem(message, hint, self.source)
        x, y = cell
        return Problem(message, hint, self.source, self.body_line + y, x + 1)

    def validate(self) -> list[Problem]:
        """Every structural problem at once (an empty list means the maze is usable)."""
        problems: list[Problem] = []
        if self.width == 0 or self.height == 0:
            return [self.problem("the maze has no blocks", "draw at least a walled room")]
        if self.width > MAX_SIZE or self.height > MAX_SIZE:
            problems.append(
                self.problem(
                    f"maze is {self.width}x{self.height} blocks, larger than {MAX_SIZE}x{MAX_SIZE}",
                    "split it or use larger cells",
                )
            )
        if self.start is None:
            problems.append(
                self.problem("no start", "mark one floor block with S or ^ > v < for the start")
            )
        elif not self.in_bounds(*self.start):
            problems.append(self.problem("start is outside the maze", "move the start inside"))
        elif self.is_wall(*self.start):
            problems.append(
                self.problem(
                    "start is inside a wall block", "move the start onto floor", self.start
                )
            )
        if self.start is not None and self.start in self.exits:
            problems.append(
                self.problem("start is on an exit", "move the start or the exit", self.start)
            )
        for e in self.exits:
            if not self.in_bounds(*e):
                problems.append(self.problem(f"exit {e} is outside the maze", "remove it"))
            elif self.is_wall(*e):
                problems.append(self.problem("exit is inside a wall block", "clear the block", e))
        problems.extend(self._boundary_problems())
        if self.start is not None and self.in_bounds(*self.start) and not self.is_wall(*self.start):
            reach = self.distances_from(self.start)
            for e in self.exits:
                if self.in_bounds(*e) and not self.is_wall(*e) and e not in reach:
                    problems.append(
                        self.problem(
                            "exit cannot be reached from the start",
                            "open a path to it or remove the E",
                            e,
                        )
                    )
        return problems

    def _boundary_problems(self) -> Iterable[Problem]:
        w, h = self.width, self.height
        seen: set[Cell] = set()
        edge = [(x, 0) for x in range(w)] + [(x, h - 1) for x in range(w)]
        edge += [(0, y) for y in range(h)] + [(w - 1, y) for y in range(h)]
        for cell in sorted(set(edge), key=lambda c: (c[1], c[0])):
            if cell in seen:
                continue
            seen.add(cell)
            if not self.is_wall(*cell) and cell not in self.exits and cell != self.start:
                yield self.problem(
                    "open floor on the outer boundary: the robot could leave the maze",
                    "make it a # wall or an E exit",
                    cell,
                )
            elif cell == self.start and not self.is_wall(*cell):
                yield self.problem(
                    "start on the outer boundary: the robot could leave the maze",
                    "move the start inside and close the boundary with #",
                    cell,
                )

    def notes(self) -> list[str]:
        """Things worth saying about a valid maze."""
        if not self.exits:
            return ["no exits: free exploration (runs end at their time limit)"]
        return []


def default_heading(maze: Maze, cell: Cell) -> str:
    """The heading a start without one gets: its only open side, else up (micromouse style)."""
    open_sides = [
        name for name, (dx, dy) in HEADINGS.items() if not maze.is_wall(cell[0] + dx, cell[1] + dy)
    ]
    return open_sides[0] if len(open_sides) == 1 else "up"
