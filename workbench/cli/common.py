"""Helpers shared by the sub-commands."""

from __future__ import annotations

import argparse
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


def db_option(parser: argparse.ArgumentParser, top: bool = False) -> None:
    """``--db URL``: given before or after the command (a command's own --db wins)."""
    parser.add_argument(
        "--db",
        metavar="URL",
        default=None if top else argparse.SUPPRESS,
        help="keep progress, sign-offs and the roster in this PostgreSQL database "
        "(postgresql://USER@HOST/DBNAME), shared by every lab server of a course (default: "
        "$WORKBENCH_DB, else the SQLite file in the data folder)",
    )


def error(message: str) -> None:
    print(f"workbench: {message}", file=sys.stderr)
