"""The names pictures are saved under: one per maze for ``eval`` and ``grade``, and the
app's names in the workspace's ``pictures/`` folder.

The rule for one picture per maze: with one maze the picture goes to the file given; with
several, each maze's goes beside it as ``STEM-MAZE.EXT``, where ``MAZE`` is the maze's file
name without its suffix (``report.svg`` with ``web`` and ``erobotic``: ``report-web.svg`` and
``report-erobotic.svg``), numbered ``-2``, ``-3``... when two mazes share a name.
"""

from __future__ import annotations

import re
from collections.abc import Sequence
from pathlib import Path

#: the workspace folder the app saves pictures in
PICTURES_FOLDER = "pictures"
_UNSAFE = re.compile(r"[^A-Za-z0-9_.-]+")


def slug(text: str, fallback: str = "run") -> str:
    """``text`` as a piece of a file name: letters, digits, ``_.-``; at most 40 of them."""
    cleaned = _UNSAFE.sub("-", text).strip("-.")[:40].strip("-.")
    return cleaned or fallback


def per_maze(target: str | Path, mazes: Sequence[str]) -> list[Path]:
    """The picture of each maze in ``mazes`` (as typed: a path or a bundled name)."""
    path = Path(target)
    if len(mazes) == 1:
        return [path]
    out: list[Path] = []
    seen: dict[str, int] = {}
    for maze in mazes:
        name = slug(Path(maze).stem, "maze")
        seen[name] = seen.get(name, 0) + 1
        if seen[name] > 1:
            name = f"{name}-{seen[name]}"
        out.append(path.with_name(f"{path.stem}-{name}{path.suffix}"))
    return out


def app_picture_name(record: str | Path, kind: str, fmt: str = "svg") -> str:
    """Where the app saves a picture of the record: ``pictures/RECORD-KIND.svg``."""
    return f"{PICTURES_FOLDER}/{slug(Path(record).stem)}-{kind}.{fmt}"


def app_compare_name(maze: str, count: int, fmt: str = "svg") -> str:
    """Where the app saves the runs of a maze side by side: ``pictures/MAZE-N-runs.svg``."""
    return f"{PICTURES_FOLDER}/{slug(maze, 'maze')}-{count}-runs.{fmt}"
