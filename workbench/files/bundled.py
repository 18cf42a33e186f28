"""Where the files that come with the workbench are (mazes, example programs, the labs'
starters), and the maze a session starts on."""

from __future__ import annotations

from pathlib import Path

import workbench

#: the bundled maze files (beside the package, as in a source checkout or an editable install)
MAZE_DIR = Path(workbench.__file__).resolve().parent.parent / "mazes"
#: the example VIPLE programs, and the starter FSMs the labs hand out to complete
PROGRAM_DIR = MAZE_DIR.parent / "programs"
STARTER_DIR = MAZE_DIR.parent / "labs" / "starters"
#: the maze the app and ``workbench serve`` open when no maze is named (the Unity simulator's)
DEFAULT_MAZE = "unity-default.txt"


def default_maze_path() -> Path:
    return MAZE_DIR / DEFAULT_MAZE


def maze_path(typed: str) -> str:
    """The maze file ``typed`` names: the path itself when it exists, else a bundled maze of
    that name (``web`` or ``web.txt``: ``mazes/web.txt``), else ``typed`` as it is (so that
    reading it says what is missing)."""
    if Path(typed).exists() or "/" in typed or "\\" in typed:
        return typed
    for name in (typed, f"{typed}.txt"):
        candidate = MAZE_DIR / name
        if candidate.is_file():
            return str(candidate)
    return typed
