"""The workbench maze text format: optional YAML front matter, then a grid of blocks.

```
---
name: Corridor
profile: unity
---
#####
#S.E#
#####
```
``#`` wall, ``.`` or space floor, ``S`` start facing right (or ``^ > v <``), ``E`` exit.
"""

from __future__ import annotations

import os

import yaml

from workbench.files.atomic import write_text_atomic
from workbench.files.bidi import bidi_problem
from workbench.files.bounded import MAZE_LIMITS, BoundedFileError, check_text, load_yaml
from workbench.files.terminal import terminal_problem

from .maze import FLOOR, MAX_SIZE, PROFILES, WALL, Maze, MazeError, Problem

START_CHARS = {"S": "right", "^": "up", ">": "right", "v": "down", "<": "left"}
HEADING_CHARS = {"up": "^", "right": "S", "down": "v", "left": "<"}
FRONT_MATTER_KEYS = ("name", "description", "profile", "cell")
CHAR_HINT = "use # wall, . floor, S start, E exit"


def _front_matter(lines: list[str], source: str) -> tuple[dict, int, list[Problem]]:
    """Return (metadata, index of the first grid line, problems)."""
    if not lines or lines[0].strip() != "---":
        return {}, 0, []
    for end in range(1, len(lines)):
        if lines[end].strip() == "---":
            break
    else:
        return (
            {},
            len(lines),
            [
                Problem(
                    "front matter is never closed",
                    "end the header with a line holding only ---",
                    source,
                    1,
                    1,
                )
            ],
        )
    text = "\n".join(lines[1:end])
    try:
        meta = load_yaml(text, source, MAZE_LIMITS, first_line=2) if text.strip() else {}
    except BoundedFileError as exc:
        return {}, end + 1, MazeError.refused(exc).problems
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        line = mark.line + 2 if mark is not None else 2
        col = mark.column + 1 if mark is not None else 1
        reason = getattr(exc, "problem", None) or "invalid YAML"
        return (
            {},
            end + 1,
            [
                Problem(
                    f"front matter is not valid YAML: {reason}", "fix the header", source, line, col
                )
            ],
        )
    if not isinstance(meta, dict):
        return (
            {},
            end + 1,
            [
                Problem(
                    "front matter must be key: value lines",
                    f"use the keys {', '.join(FRONT_MATTER_KEYS)}",
                    source,
                    2,
                    1,
                )
            ],
        )
    problems = []
    key_lines: dict[str, int] = {}
    for i, raw in enumerate(lines[1:end], start=2):
        key = raw.split(":", 1)[0].strip()
        key_lines.setdefault(key, i)
    for key in meta:
        if key not in FRONT_MATTER_KEYS:
            problems.append(
                Problem(
                    f"unknown front matter key {key!r}",
                    f"use {', '.join(FRONT_MATTER_KEYS)}",
                    source,
                    key_lines.get(str(key), 2),
                    1,
                )
            )
    profile = meta.get("profile")
    if profile is not None and profile not in PROFILES:
        problems.append(
            Problem(
                f"unknown profile {profile!r}",
                f"use one of {', '.join(PROFILES)}",
                source,
                key_lines.get("profile", 2),
                1,
            )
        )
    cell = meta.get("cell")
    if cell is not None and (
        isinstance(cell, bool) or not isinstance(cell, int | float) or cell <= 0
    ):
        problems.append(
            Problem(
                f"cell must be a positive number, not {cell!r}",
                "give the block size in profile units, e.g. cell: 1.0",
                source,
                key_lines.get("cell", 2),
                1,
            )
        )
    for key in ("name", "description"):
        if key in meta and not isinstance(meta[key], str):
            meta[key] = str(meta[key])
        text = str(meta.get(key) or "")
        what = f"the maze's {key}"
        problem = bidi_problem(text, what) or terminal_problem(text, what, key != "name")
        if problem:
            problems.append(
                Problem(problem, "type it again without it", source, key_lines.get(key, 2), 1)
            )
    return meta, end + 1, problems


def parse_maze(text: str, source: str = "<maze>") -> Maze:
    """Parse the workbench format; raise :class:`MazeError` with every problem found.

    Structural checks (boundary, reachability) are not done here: see :meth:`Maze.validate`.
    The text's size and characters are checked first, and a grid larger than the largest maze
    is refused before any block is read.
    """
    try:
        text = check_text(text, source, MAZE_LIMITS)
    except BoundedFileError as exc:
        raise MazeError.refused(exc) from None
    lines = text.splitlines()
    meta, first, problems = _front_matter(lines, source)
    body = lines[first:]
    lead = 0
    while lead < len(body) and not body[lead].strip():
        lead += 1
    body = body[lead:]
    while body and not body[-1].strip():
        body.pop()
    body_line = first + lead + 1
    if not body:
        problems.append(
            Problem("no maze grid found", "draw the maze with # and . after the header", source)
        )
        raise MazeError(problems)
    _check_grid_size(body, body_line, source)
    width = max(len(r) for r in body)
    rows: list[str] = []
    starts: list[tuple[int, int, str]] = []
    exits: list[tuple[int, int]] = []
    for y, raw in enumerate(body):
        out = []
        for x, ch in enumerate(raw.ljust(width)):
            if ch == WALL:
                out.append(WALL)
                continue
            out.append(FLOOR)
            if ch in (FLOOR, " "):
                continue
            if ch in START_CHARS:
                starts.append((x, y, START_CHARS[ch]))
            elif ch == "E":
                exits.append((x, y))
            elif ch == "\t":
                problems.append(
                    Problem(
                        "tab character",
                        "replace tabs with spaces or .",
                        source,
                        body_line + y,
                        x + 1,
                    )
                )
            else:
                problems.append(
                    Problem(f"unknown character {ch!r}", CHAR_HINT, source, body_line + y, x + 1)
                )
        rows.append("".join(out))
    if len(starts) > 1:
        for x, y, _ in starts:
            problems.append(
                Problem(
                    f"one of {len(starts)} starts",
                    "keep exactly one S (or ^ > v <)",
                    source,
                    body_line + y,
                    x + 1,
                )
            )
    if problems:
        raise MazeError(problems)
    start = (starts[0][0], starts[0][1]) if starts else None
    heading = starts[0][2] if starts else "right"
    return Maze(
        rows=tuple(rows),
        start=start,
        heading=heading,
        exits=tuple(exits),
        name=str(meta.get("name") or ""),
        description=str(meta.get("description") or ""),
        profile=meta.get("profile"),
        cell=float(meta["cell"]) if meta.get("cell") is not None else None,
        source=source,
        body_line=body_line,
    )


def _check_grid_size(body: list[str], body_line: int, source: str) -> None:
    """Refuse a grid with more rows or columns than a maze may have, before reading it."""
    if len(body) > MAX_SIZE:
        raise MazeError(
            [
                Problem(
                    f"the grid has {len(body):,} rows, more than the largest maze "
                    f"({MAX_SIZE}x{MAX_SIZE} blocks)",
                    "split the maze or use larger cells",
                    source,
                    body_line + MAX_SIZE,
                    1,
                )
            ]
        )
    for y, raw in enumerate(body):
        if len(raw) > MAX_SIZE:
            raise MazeError(
                [
                    Problem(
                        f"the row is {len(raw):,} blocks wide, wider than the largest maze "
                        f"({MAX_SIZE}x{MAX_SIZE} blocks)",
                        "split the maze or use larger cells",
                        source,
                        body_line + y,
                        MAX_SIZE + 1,
                    )
                ]
            )


def format_maze(maze: Maze, front_matter: bool = True) -> str:
    """The maze in the workbench format (front matter only for the keys that are set)."""
    out: list[str] = []
    if front_matter:
        meta = {k: getattr(maze, k) for k in FRONT_MATTER_KEYS if getattr(maze, k)}
        if meta:
            out.append("---")
            out.append(
                yaml.safe_dump(meta, sort_keys=False, allow_unicode=True, width=100).rstrip()
            )
            out.append("---")
    for y, row in enumerate(maze.rows):
        chars = list(row)
        for x, yy in maze.exits:
            if yy == y:
                chars[x] = "E"
        if maze.start is not None and maze.start[1] == y:
            chars[maze.start[0]] = HEADING_CHARS[maze.heading]
        out.append("".join(chars))
    return "\n".join(out) + "\n"


def check_names(path: str | os.PathLike, maze: Maze) -> None:
    """:class:`MazeError` when the maze's name or description, or the file name it is to be
    saved under, holds a bidi control (see :mod:`workbench.files.bidi`) or a control
    character a terminal acts on (:mod:`workbench.files.terminal`)."""
    checks = (
        (maze.name, "the maze's name", False),
        (maze.description, "the maze's description", True),
        (os.path.basename(os.fspath(path)), "the file name", False),
    )
    problems = [
        Problem(problem, "type it again without it", str(path))
        for text, what, lines in checks
        if (problem := bidi_problem(text, what) or terminal_problem(text, what, lines))
    ]
    if problems:
        raise MazeError(problems)


def write_maze(path: str | os.PathLike, maze: Maze) -> None:
    check_names(path, maze)
    write_text_atomic(path, format_maze(maze))
