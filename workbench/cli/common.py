"""Helpers shared by the sub-commands."""

from __future__ import annotations

import sys
from pathlib import Path

import workbench

MAZE_DIR = Path(workbench.__file__).resolve().parent.parent / "mazes"


def default_maze_path() -> Path:
    return MAZE_DIR / "unity-default.txt"


def error(message: str) -> None:
    print(f"workbench: {message}", file=sys.stderr)
