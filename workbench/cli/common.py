"""Helpers shared by the sub-commands."""

from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path

from workbench.sim.profiles import REPORT_MS_MAX, REPORT_MS_MIN, check_report_ms


def runs_home() -> Path:
    """Where the app keeps run records: $XDG_DATA_HOME/viple-workbench/runs."""
    base = os.environ.get("XDG_DATA_HOME") or os.path.join(
        os.path.expanduser("~"), ".local", "share"
    )
    return Path(base) / "viple-workbench" / "runs"


def new_runs_dir() -> str:
    """A folder for this app session's run records (created when the first run starts)."""
    return str(runs_home() / time.strftime("%Y%m%d-%H%M%S"))


def size(text: str) -> int | None:
    """A size option's value: bytes, or None for 0 (no limit)."""
    from workbench.files.sizes import parse_size

    try:
        value = parse_size(text)
    except ValueError as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None
    return value or None


def record_quota_options(parser: argparse.ArgumentParser) -> None:
    """``--record-cap`` and ``--runs-quota``: how much room run records may take."""
    from workbench.control.recording import RECORD_CAP, RUNS_QUOTA, shown_size

    parser.add_argument(
        "--record-cap",
        type=size,
        default=RECORD_CAP,
        metavar="SIZE",
        help="the largest one run record may grow; past it the run goes on unrecorded "
        f"(e.g. 20M; 0: no limit; default {shown_size(RECORD_CAP)})",
    )
    parser.add_argument(
        "--runs-quota",
        type=size,
        default=RUNS_QUOTA,
        metavar="SIZE",
        help="the most all run records of a student (their ~/runs on a server) may take; "
        f"past it runs go unrecorded (0: no limit; default {shown_size(RUNS_QUOTA)})",
    )


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


def report_ms(text: str) -> int:
    """``--report-ms``'s value: whole milliseconds in the allowed range."""
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(
            f"{text[:20]!r} is not a whole number of milliseconds"
        ) from None
    try:
        return check_report_ms(value)
    except ValueError as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None


def report_ms_option(parser: argparse.ArgumentParser) -> None:
    """How often a VIPLE program file gets its sensor reports when it runs here."""
    parser.add_argument(
        "--report-ms",
        type=report_ms,
        metavar="MS",
        help="a VIPLE program's sensors are reported every MS milliseconds, as VIPLE's "
        f"simulator does ({REPORT_MS_MIN}-{REPORT_MS_MAX}; default: the profile's, 250)",
    )


def error(message: str) -> None:
    print(f"workbench: {message}", file=sys.stderr)


def upload_options(parser: argparse.ArgumentParser) -> None:
    """``--upload-cap``, ``--workspace-quota`` and ``--workspace-files``: what a student may
    keep in their workspace by SFTP and scp."""
    from workbench.files.sizes import shown_size
    from workbench.files.workspace_files import FILE_CAP, QUOTA_BYTES, QUOTA_FILES

    parser.add_argument(
        "--upload-cap",
        type=size,
        default=FILE_CAP,
        metavar="SIZE",
        help="the largest file a student may upload by SFTP or scp "
        f"(e.g. 5M; 0: no limit; default {shown_size(FILE_CAP)})",
    )
    parser.add_argument(
        "--workspace-quota",
        type=size,
        default=QUOTA_BYTES,
        metavar="SIZE",
        help="the most a student's own files in their workspace may take, run records not "
        f"counted (0: no limit; default {shown_size(QUOTA_BYTES)})",
    )
    parser.add_argument(
        "--workspace-files",
        type=_count,
        default=QUOTA_FILES,
        metavar="N",
        help="the most files and folders a student may keep in their workspace, run records "
        f"not counted (0: no limit; default {QUOTA_FILES})",
    )


def _count(text: str) -> int:
    if not text.strip().isdigit():
        raise argparse.ArgumentTypeError(f"{text!r} is not a number of files (e.g. 2000)")
    return int(text)
