"""The maze editor's model: a cursor, edits with undo/redo, live validation, saving.

Every edit makes a new immutable :class:`Maze`; the undo and redo stacks hold whole mazes, so
undo is exact and cheap. Each maze is kept with the one it was made from by hand (the maze
opened, or the last one New or Generate made), so the editor can say how many blocks the
student added or removed by hand (:meth:`MazeEditor.hand_blocks`). The editor never loses
work: a failed save raises :class:`EditorError` with a readable reason and leaves the edited
maze in memory.
"""

from __future__ import annotations

import os
import re
from dataclasses import dataclass, replace
from pathlib import Path

from workbench.files.workspace import LOCAL, FileAccess, OutsideWorkspace

from .generate import EXITS, MAX_CELLS, MIN_CELLS, STYLES, generate
from .maze import FLOOR, HEADINGS, MAX_SIZE, WALL, Cell, Maze, MazeError, Problem
from .mazeio import format_for_path, maze_bytes

#: the order ``s`` cycles the start's heading through when pressed again on the start
HEADING_CYCLE: tuple[str, ...] = tuple(HEADINGS)
MIN_BLOCKS = 3
UNDO_LIMIT = 1000


class EditorError(ValueError):
    """An edit or save that could not be done, with a reason a student can act on."""


@dataclass(frozen=True)
class Finding:
    """One validation problem of the edited maze, at a block when it has one."""

    message: str
    hint: str
    cell: Cell | None = None

    def __str__(self) -> str:
        where = f"({self.cell[0]}, {self.cell[1]}) " if self.cell is not None else ""
        return f"{where}{self.message}: {self.hint}"


def finding_of(maze: Maze, problem: Problem) -> Finding:
    """A maze problem with its file position turned back into the block it names."""
    cell = None
    if problem.line and problem.column:
        x, y = problem.column - 1, problem.line - maze.body_line
        if maze.in_bounds(x, y):
            cell = (x, y)
    return Finding(problem.message, problem.hint, cell)


def parse_size(width: str | int, height: str | int, low: int, high: int, unit: str) -> Cell:
    """Two sizes typed by a student as whole numbers within ``low..high``; else EditorError."""
    values = []
    for label, raw in (("width", width), ("height", height)):
        text = str(raw).strip()
        if not text:
            raise EditorError(f"{label} is empty: type a whole number of {unit} ({low}-{high})")
        if not text.isdigit():
            raise EditorError(f"{label} {text!r} is not a whole number of {unit} ({low}-{high})")
        value = int(text)
        if not low <= value <= high:
            raise EditorError(f"{label} must be {low} to {high} {unit}, not {value}")
        values.append(value)
    return values[0], values[1]


def parse_seed(raw: str | int) -> int:
    text = str(raw).strip()
    if not text.isdigit():
        raise EditorError(f"seed {text!r} is not a whole number 0 or more")
    return int(text)


@dataclass(frozen=True)
class GenerateOptions:
    """What the generate dialog asks for: a size in cells, a seed, a style and the exits."""

    width: int = 8
    height: int = 8
    seed: int = 1
    style: str = "perfect"
    exit: str = "boundary"

    @classmethod
    def parse(
        cls, width: str | int, height: str | int, seed: str | int, style: str, exit: str
    ) -> GenerateOptions:
        """The options as typed; EditorError names the first field that is wrong."""
        w, h = parse_size(width, height, MIN_CELLS, MAX_CELLS, "cells")
        if style not in STYLES:
            raise EditorError(f"unknown style {style!r}: use one of {', '.join(STYLES)}")
        if exit not in EXITS:
            raise EditorError(f"unknown exit option {exit!r}: use one of {', '.join(EXITS)}")
        return cls(w, h, parse_seed(seed), style, exit)


def blank_maze(width: int, height: int) -> Maze:
    """All floor inside a closed wall boundary, the start at (1, 1) facing right."""
    if not (MIN_BLOCKS <= width <= MAX_SIZE and MIN_BLOCKS <= height <= MAX_SIZE):
        raise EditorError(
            f"a maze is {MIN_BLOCKS} to {MAX_SIZE} blocks a side, not {width}x{height}"
        )
    edge = WALL * width
    inside = WALL + FLOOR * (width - 2) + WALL
    rows = (edge, *([inside] * (height - 2)), edge)
    return Maze(rows=rows, start=(1, 1), heading="right")


class MazeEditor:
    """The maze being edited, where the cursor is, what can be undone, and where it is saved."""

    def __init__(
        self, maze: Maze, path: str | os.PathLike | None = None, files: FileAccess = LOCAL
    ) -> None:
        self.files = files
        self.maze = maze
        self.path: str | None = os.fspath(path) if path is not None else None
        #: the maze the editor was opened with, and the one last saved (or opened)
        self.opened = maze
        self.saved = maze
        self.cursor: Cell = self._clamp(maze.start if maze.start is not None else (0, 0))
        #: the maze the current one (and the one last saved) was made from by hand
        self._base = maze
        self._saved_base = maze
        self._undo: list[tuple[Maze, Maze]] = []
        self._redo: list[tuple[Maze, Maze]] = []
        self._findings: tuple[Maze, list[Finding]] | None = None

    # -- state ---------------------------------------------------------------------------
    @property
    def dirty(self) -> bool:
        """True when the maze differs from the one opened or last saved."""
        return self.maze != self.saved

    @property
    def can_undo(self) -> bool:
        return bool(self._undo)

    @property
    def can_redo(self) -> bool:
        return bool(self._redo)

    @property
    def problems(self) -> list[Finding]:
        """The maze's validation problems, recomputed only when the maze changed."""
        if self._findings is None or self._findings[0] is not self.maze:
            found = [finding_of(self.maze, p) for p in self.maze.validate()]
            self._findings = (self.maze, found)
        return list(self._findings[1])

    @property
    def valid(self) -> bool:
        return not self.problems

    def notes(self) -> list[str]:
        return self.maze.notes() if self.valid else []

    def title(self) -> str:
        """What the maze is called: its name, else its file, else "new maze"."""
        if self.maze.name:
            return self.maze.name
        if self.path:
            return Path(self.path).stem
        return "new maze"

    def handover(self, discard: bool = False) -> tuple[Maze | None, str]:
        """On leaving: the maze the robot should now run on (None: keep the old one) and why.

        With ``discard`` the unsaved edits are dropped and the last saved maze counts.
        """
        maze = self.saved if discard else self.maze
        if maze == self.opened:
            return None, ""
        problems = maze.validate()
        if problems:
            count = f"{len(problems)} problem{'s' if len(problems) != 1 else ''}"
            return None, f"the maze has {count}, so the robot stays on the previous maze"
        if not maze.name:
            maze = replace(maze, name=self.title())
        return maze, ""

    def suggested_path(self) -> str:
        """Where save as proposes to write: the current file, else a name from the title."""
        if self.path:
            return self.files.shown(self.path)
        slug = re.sub(r"[^a-z0-9]+", "-", self.title().lower()).strip("-") or "maze"
        return f"{slug}.txt"

    # -- cursor --------------------------------------------------------------------------
    def _clamp(self, cell: Cell) -> Cell:
        x = min(max(cell[0], 0), max(self.maze.width - 1, 0))
        y = min(max(cell[1], 0), max(self.maze.height - 1, 0))
        return (x, y)

    def move(self, dx: int, dy: int) -> Cell:
        """Move the cursor by (dx, dy) blocks, stopping at the maze's edges."""
        self.cursor = self._clamp((self.cursor[0] + dx, self.cursor[1] + dy))
        return self.cursor

    def move_to(self, cell: Cell) -> Cell:
        self.cursor = self._clamp(cell)
        return self.cursor

    # -- edits ---------------------------------------------------------------------------
    def hand_blocks(self, discard: bool = False) -> int:
        """How many blocks of the maze (with ``discard``: of the one last saved) were walled
        or cleared by hand: the blocks that differ from the maze it was made from (the one
        opened, or the last one New or Generate made). An edit undone, or made back by hand,
        is not counted."""
        maze, base = (self.saved, self._saved_base) if discard else (self.maze, self._base)
        if (maze.width, maze.height) != (base.width, base.height):
            return 0  # not made from it by hand (a maze is resized only whole)
        return sum(
            maze.is_wall(x, y) != base.is_wall(x, y)
            for y in range(maze.height)
            for x in range(maze.width)
        )

    def _apply(self, maze: Maze, base: Maze | None = None) -> bool:
        if maze == self.maze:
            return False
        self._undo.append((self.maze, self._base))
        del self._undo[:-UNDO_LIMIT]
        self._redo.clear()
        self.maze = maze
        if base is not None:
            self._base = base
        self.cursor = self._clamp(self.cursor)
        return True

    def toggle_wall(self, cell: Cell | None = None) -> bool:
        """Wall <-> floor at ``cell`` (default: the cursor); an exit on a new wall goes.

        The start's block stays floor (a maze file cannot hold a start inside a wall):
        raises :class:`EditorError` saying to move the start first.
        """
        x, y = self.move_to(cell) if cell is not None else self.cursor
        wall = not self.maze.is_wall(x, y)
        if wall and self.maze.start == (x, y):
            raise EditorError("the start is on this block: move the start (s) before walling it")
        return self._apply(self.maze.with_block(x, y, wall))

    def set_start(self) -> str:
        """Put the start on the cursor (its block becomes floor); on the start already, turn
        it to the next heading."""
        x, y = self.cursor
        maze = self.maze.with_block(x, y, False)
        if maze.start == (x, y):
            heading = HEADING_CYCLE[(HEADING_CYCLE.index(maze.heading) + 1) % len(HEADING_CYCLE)]
        else:
            heading = maze.heading
        self._apply(maze.with_start(x, y, heading))
        return heading

    def toggle_exit(self) -> bool:
        """Add an exit at the cursor (its block becomes floor), or remove the one there.

        Returns True when an exit is there now.
        """
        x, y = self.cursor
        present = not self.maze.is_exit(x, y)
        maze = self.maze.with_block(x, y, False) if present else self.maze
        self._apply(maze.with_exit(x, y, present))
        return present

    def new(self, width: int, height: int) -> None:
        """Start a new maze of ``width`` x ``height`` blocks (undoable; saved under a new path)."""
        self._replace_whole(blank_maze(width, height))

    def generate(self, width: int, height: int, seed: int, style: str, exit: str) -> None:
        """A generated maze of ``width`` x ``height`` cells (undoable; saved under a new path)."""
        if style not in STYLES:
            raise EditorError(f"unknown style {style!r}: use one of {', '.join(STYLES)}")
        if exit not in EXITS:
            raise EditorError(f"unknown exit option {exit!r}: use one of {', '.join(EXITS)}")
        try:
            maze = generate(width, height, seed, style, exit)
        except ValueError as exc:
            raise EditorError(str(exc)) from None
        self._replace_whole(maze)

    def _replace_whole(self, maze: Maze) -> None:
        self._apply(maze, base=maze)
        self.path = None
        self.cursor = self._clamp(maze.start if maze.start is not None else (0, 0))

    def undo(self) -> bool:
        if not self._undo:
            return False
        self._redo.append((self.maze, self._base))
        self.maze, self._base = self._undo.pop()
        self.cursor = self._clamp(self.cursor)
        return True

    def redo(self) -> bool:
        if not self._redo:
            return False
        self._undo.append((self.maze, self._base))
        self.maze, self._base = self._redo.pop()
        self.cursor = self._clamp(self.cursor)
        return True

    # -- saving --------------------------------------------------------------------------
    def save(self, path: str | os.PathLike | None = None) -> str:
        """Write the maze atomically to ``path`` (default: where it was last saved).

        Returns the path written. On failure raises :class:`EditorError`; the maze, the path
        and the dirty flag stay as they were.
        """
        target = os.fspath(path) if path is not None else self.path
        if target is None or not str(target).strip():
            raise EditorError("no file name yet: use save as and type a path")
        files = self.files
        try:
            target = os.fspath(files.for_writing(target))
        except OutsideWorkspace as exc:
            raise EditorError(f"cannot save there: {exc}") from None
        shown = files.shown(target)
        if os.path.isdir(target):
            raise EditorError(f"{shown} is a folder: add a file name, e.g. {shown}/maze.txt")
        folder = os.path.dirname(target) or "."
        if not os.path.isdir(folder):
            raise EditorError(
                f"cannot save to {shown}: the folder {files.shown(folder)} does not exist"
            )
        try:
            files.write_bytes(target, maze_bytes(target, self.maze, format_for_path(target)))
        except OutsideWorkspace as exc:  # no room left in the workspace
            raise EditorError(f"cannot save: {exc}") from None
        except MazeError as exc:
            reasons = "; ".join(f"{p.message} ({p.hint})" for p in exc.problems)
            raise EditorError(f"cannot save as {shown}: {reasons}") from None
        except OSError as exc:
            reason = exc.strerror or str(exc)
            raise EditorError(
                f"cannot save to {shown}: {reason}; the maze is still here, "
                "try save as with another path"
            ) from None
        self.path = target
        self.saved = self.maze
        self._saved_base = self._base
        return target
