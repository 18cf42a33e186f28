"""Helpers shared by the sub-commands."""

from __future__ import annotations

import os
import sys
import time
from pathlib import Path


def runs_home() -> Path:
    """Where the app keeps run records: $XDG_DATA_HOME/viple-workbench/runs."""
    base = os.environ.get("XDG_DATA_HOME") or os.path.join(
        os.path.expanduser("~"), ".local", "share"
    )
    return Path(base) / "viple-workbench" / "runs"


def new_runs_dir() -> str:
    """A folder for this app session's run records (created when the first run starts)."""
    return str(runs_home() / time.strftime("%Y%m%d-%H%M%S"))


def error(message: str) -> None:
    print(f"workbench: {message}", file=sys.stderr)
