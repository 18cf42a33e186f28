"""Open a maze file of any supported format (detected from its content) as a block ``Maze``,
and save a maze in the workbench, micromouse text or ``.maz`` format.
"""

from __future__ import annotations

import os
import re
from dataclasses import replace
from pathlib import Path

from workbench.files.atomic import write_bytes_atomic
from workbench.files.bounded import (
    MAZE_LIMITS,
    BoundedFileError,
    decode_text,
    read_bytes,
    strip_bom,
)

from .maz import format_maz, parse_maz
from .maze import Maze, MazeError, Problem
from .mazefile import check_names, format_maze, parse_maze
from .micromouse import format_micromouse, parse_micromouse, parse_mms_map, parse_mms_num
from .wallmaze import to_blocks

FORMATS = ("workbench", "micromouse", "mms-map", "mms-num", "maz")
WRITE_FORMATS = ("workbench", "micromouse", "maz")
WALL_READERS = {"micromouse": parse_micromouse, "mms-map": parse_mms_map, "mms-num": parse_mms_num}
_NUM_LINE = re.compile(r"\s*\d+(\s+\d+){5}\s*")
_CONTROL = set(range(32)) - {9, 10, 13}


def detect_format(data: bytes) -> str:
    """The format of a file's content: binary -> maz, then by the first non-blank line."""
    data = strip_bom(data)
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError:
        return "maz"
    if b"\0" in data or (len(data) == 256 and any(b in _CONTROL for b in data)):
        return "maz"
    first = next((line for line in text.splitlines() if line.strip()), "")
    if first.startswith("o"):
        return "micromouse"
    if first.startswith("+"):
        return "mms-map"
    if _NUM_LINE.fullmatch(first):
        return "mms-num"
    return "workbench"


def _unknown(fmt: str, known: tuple[str, ...], source: str) -> MazeError:
    return MazeError([Problem(f"unknown format {fmt!r}", f"use one of {', '.join(known)}", source)])


def load_maze(path: str | os.PathLike, fmt: str | None = None) -> Maze:
    """Read ``path`` as ``fmt`` (or the detected format); errors are :class:`MazeError`."""
    p = Path(path)
    source = str(p)
    if fmt is not None and fmt not in FORMATS:
        raise _unknown(fmt, FORMATS, source)
    try:
        data = read_bytes(p, MAZE_LIMITS, source)
    except BoundedFileError as exc:
        raise MazeError.refused(exc) from None
    if fmt is None:
        fmt = detect_format(data)
        if fmt == "maz" and len(data) != 256:
            raise _binary(data, source)
    if fmt == "maz":
        maze = to_blocks(parse_maz(data, source))
    else:
        try:
            text = decode_text(data, source, MAZE_LIMITS)
        except BoundedFileError as exc:
            raise MazeError.refused(exc) from None
        if fmt == "workbench":
            maze = parse_maze(text, source=source)
        else:
            maze = to_blocks(WALL_READERS[fmt](text, source))
    return maze if maze.name else replace(maze, name=p.stem)


def _binary(data: bytes, source: str) -> MazeError:
    """The error for a file that is neither text nor a .maz maze, at its first binary byte."""
    line = column = None
    reason = ""
    try:
        decode_text(data, source, MAZE_LIMITS)
    except BoundedFileError as exc:
        line, column, reason = exc.line, exc.column, f": {exc.message}"
    return MazeError(
        [
            Problem(
                "a binary file, neither UTF-8 text nor a .maz maze "
                f"(256 bytes; this one is {len(data)} bytes){reason}",
                f"check the file; the formats read are {', '.join(FORMATS)}",
                source,
                line or 0,
                column or 0,
            )
        ]
    )


def format_for_path(path: str | os.PathLike) -> str:
    """The format a file is written in when none is asked for: by its extension."""
    return "maz" if Path(path).suffix.lower() == ".maz" else "workbench"


def save_maze(path: str | os.PathLike, maze: Maze, fmt: str = "workbench") -> None:
    """Write ``maze`` atomically; MazeError when the format cannot hold it."""
    write_bytes_atomic(path, maze_bytes(path, maze, fmt))


def maze_bytes(path: str | os.PathLike, maze: Maze, fmt: str = "workbench") -> bytes:
    """The bytes of ``maze`` saved at ``path`` in ``fmt``; MazeError when the format cannot
    hold it (or the names cannot be saved, :func:`~.mazefile.check_names`)."""
    if fmt not in WRITE_FORMATS:
        raise _unknown(fmt, WRITE_FORMATS, str(path))
    check_names(path, maze)
    if fmt == "maz":
        return format_maz(maze)
    if fmt == "micromouse":
        return format_micromouse(maze).encode("utf-8")
    return format_maze(maze).encode("utf-8")
