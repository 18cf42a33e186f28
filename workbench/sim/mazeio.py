"""Open a maze file of any supported format (detected from its content) as a block ``Maze``."""

from __future__ import annotations

import os
from dataclasses import replace
from pathlib import Path

from .maze import Maze, MazeError, Problem
from .mazefile import parse_maze

FORMATS = ("workbench",)


def load_maze(path: str | os.PathLike, fmt: str | None = None) -> Maze:
    """Read ``path`` as ``fmt`` (or the detected format); errors are :class:`MazeError`."""
    p = Path(path)
    try:
        data = p.read_bytes()
    except OSError as exc:
        raise MazeError(
            [Problem(f"cannot read: {exc.strerror}", "check the path", str(p))]
        ) from None
    fmt = fmt or "workbench"
    if fmt not in FORMATS:
        raise MazeError(
            [Problem(f"unknown format {fmt!r}", f"use one of {', '.join(FORMATS)}", str(p))]
        )
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError:
        raise MazeError([Problem("not a UTF-8 text file", "check the file", str(p))]) from None
    maze = parse_maze(text, source=str(p))
    return maze if maze.name else replace(maze, name=p.stem)
