"""``workbench picture``: run records drawn as pictures for a lab report, and the
``--picture FILE`` option that ``run``, ``eval``, ``viple run`` and ``grade`` share."""

from __future__ import annotations

import argparse
import contextlib
import dataclasses
import os
import sys
import tempfile
from collections.abc import Iterator, Sequence
from pathlib import Path
from typing import TYPE_CHECKING

from workbench.files.terminal import terminal_safe
from workbench.pictures import KIND_NAMES

if TYPE_CHECKING:
    from workbench.control.headless import RunSpec

# (the pictures' code is imported where a picture is drawn: the command line is imported by
# the served app's entry point, whose start-up the pictures must not slow)


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "picture",
        help="draw run records as a picture (SVG or PNG) for a lab report",
        description="Draw one run's path on its maze (path), its sensors, wheel powers and "
        "states over time (time), or several runs on one maze side by side (compare).",
    )
    p.add_argument("records", nargs="+", metavar="RECORD.jsonl")
    p.add_argument("-o", "--output", required=True, metavar="FILE.svg|FILE.png")
    p.add_argument(
        "--kind",
        choices=list(KIND_NAMES),
        help="default: path for one record, compare for several",
    )
    p.add_argument(
        "--at",
        type=float,
        action="append",
        default=[],
        metavar="T",
        help="with path: draw the sensors' beams at simulated second T (repeat for more)",
    )
    p.add_argument(
        "--maze",
        metavar="M",
        help="the runs' maze (a file, or a bundled maze by name); default: the one each "
        "record names",
    )
    p.add_argument("--size", metavar="WxH", help="in pixels (default: from the kind and maze)")
    p.set_defaults(func=cmd_picture)


def picture_option(parser: argparse.ArgumentParser, what: str) -> None:
    parser.add_argument(
        "--picture", metavar="FILE.svg|FILE.png", help=f"also draw {what} (docs/pictures.md)"
    )


def _size(text: str | None) -> tuple[int, int] | None:
    from workbench.pictures.runs import PictureError

    if not text:
        return None
    width, sep, height = text.lower().partition("x")
    if not sep or not width.isdigit() or not height.isdigit():
        raise PictureError(f"--size {terminal_safe(text)}: give it as WIDTHxHEIGHT, e.g. 1200x900")
    return int(width), int(height)


def check_target(target: str | os.PathLike) -> None:
    """Refuse, before a run, a picture file that could not be written after it."""
    from workbench.pictures.render import format_for
    from workbench.pictures.runs import PictureError

    format_for(target)
    folder = Path(target).parent
    shown = terminal_safe(os.fspath(target))
    if not folder.is_dir():
        raise PictureError(
            f"{shown}: its folder does not exist: make the folder, or save elsewhere"
        )
    if not os.access(folder, os.W_OK):
        raise PictureError(
            f"{shown}: its folder cannot be written: save it in a folder you can write to"
        )
    if Path(target).is_dir():
        raise PictureError(f"{shown}: a folder, not a file: give a file name ending .svg or .png")


def said(path: Path, kind: str) -> str:
    return f"picture ({kind}): {terminal_safe(str(path))}, {path.stat().st_size:,} bytes"


def cmd_picture(args: argparse.Namespace) -> int:
    from workbench.pictures.render import PictureSpec, format_for, save_picture
    from workbench.pictures.runs import PictureError, load_runs, read_maze

    try:
        kind = args.kind or ("path" if len(args.records) == 1 else "compare")
        maze = read_maze(args.maze) if args.maze else None
        check_target(args.output)
        spec = PictureSpec(kind, format_for(args.output), _size(args.size), tuple(args.at))
        spec.check()
        runs = load_runs(args.records, maze)
        written = save_picture(runs, args.output, spec)
    except PictureError as exc:
        print(f"workbench picture: {exc}", file=sys.stderr)
        return 2
    for run in runs:
        if run.note:
            print(f"note: {run.name}: {terminal_safe(run.note)}", file=sys.stderr)
    print(said(written, kind))
    return 0


@contextlib.contextmanager
def recorded(spec: RunSpec) -> Iterator[RunSpec]:
    """``spec`` with a record to draw from: its own ``--record``, else a temporary one."""
    if spec.record:
        yield spec
        return
    with tempfile.TemporaryDirectory(prefix="workbench-picture-") as folder:
        yield dataclasses.replace(spec, record=str(Path(folder) / "run.jsonl"))


def draw(records: Sequence[str], target: str, kind: str, prog: str, kept: bool = True) -> int:
    """Draw ``records`` at ``target``; 0, or 2 with the reason on standard error. A record
    not ``kept`` (a temporary one) is not named in the caption."""
    from workbench.pictures.render import PictureSpec, format_for, save_picture
    from workbench.pictures.runs import PictureError, load_runs

    try:
        runs = load_runs(records)
        if not kept:
            runs = [
                dataclasses.replace(r, record_words="run not kept (--record keeps it)")
                for r in runs
            ]
        written = save_picture(runs, target, PictureSpec(kind, format_for(target)))
    except PictureError as exc:
        print(f"{prog}: {exc}", file=sys.stderr)
        return 2
    print(said(written, kind), file=sys.stderr)
    return 0


def refused(target: str | None, prog: str) -> bool:
    """Check ``--picture`` before a run; True (with the reason said) when it cannot be used."""
    from workbench.pictures.runs import PictureError

    if not target:
        return False
    try:
        check_target(target)
    except PictureError as exc:
        print(f"{prog}: --picture {exc}", file=sys.stderr)
        return True
    return False


def maze_pictures(target: str, mazes: Sequence[str]) -> list[Path]:
    from workbench.pictures.naming import per_maze

    return per_maze(target, mazes)
