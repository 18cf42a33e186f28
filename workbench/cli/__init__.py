"""The ``workbench`` command: one entry point, one sub-command module per area."""

from __future__ import annotations

import argparse
import os
import sys
from collections.abc import Sequence

from workbench import __version__

from . import algorithms as algorithms_cmd
from . import maze as maze_cmd
from . import run as run_cmd
from . import serve as serve_cmd
from . import viple_client as viple_client_cmd
from .common import default_maze_path


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="workbench",
        description="VIPLE Maze Lab Workbench: maze simulator and lab workbench for ASU VIPLE.",
    )
    parser.add_argument("--version", action="version", version=f"workbench {__version__}")
    parser.add_argument("--maze", help="maze file to open (default: the bundled Unity maze)")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    maze_cmd.register(sub)
    algorithms_cmd.register(sub)
    run_cmd.register(sub)
    serve_cmd.register(sub)
    viple_client_cmd.register(sub)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    if args.command is None:
        return demo(args)
    try:
        return int(args.func(args) or 0)
    except KeyboardInterrupt:
        print("interrupted", file=sys.stderr)
        return 130
    except BrokenPipeError:
        # the reader went away (e.g. `| head`): stop quietly, as other command-line tools do
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 141


def demo(args: argparse.Namespace) -> int:
    """Without a command: show the chosen (or bundled default) maze and its check."""
    path = args.maze or str(default_maze_path())
    return maze_cmd.show_and_check(path)
