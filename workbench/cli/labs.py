"""``workbench labs check``: read lab files as the app does and report what is wrong."""

from __future__ import annotations

import argparse
import sys

from workbench.labs.model import LabFileError, load_lab


def register(sub: argparse._SubParsersAction) -> None:
    labs = sub.add_parser("labs", help="check lab files")
    inner = labs.add_subparsers(dest="labs_command", metavar="ACTION", required=True)
    check = inner.add_parser(
        "check",
        help="read lab files as the app does (exit 0 when all can be used)",
        description="Read each lab file, its mazes and its starter FSMs as the app does and "
        "print its exercises, or what is wrong and where.",
    )
    check.add_argument("files", nargs="+", metavar="FILE")
    check.set_defaults(func=cmd_check)


def cmd_check(args: argparse.Namespace) -> int:
    ok = True
    for path in args.files:
        try:
            lab = load_lab(path)
        except LabFileError as exc:
            print(exc, file=sys.stderr)
            ok = False
            continue
        print(f"{path}: {lab.title} ({len(lab.exercises)} exercises)")
    return 0 if ok else 1
