"""The ``workbench`` command: one entry point, one sub-command module per area."""

from __future__ import annotations

import argparse
import os
import sys
from collections.abc import Sequence
from pathlib import Path
from typing import TextIO, cast

from workbench import __version__
from workbench.files.bundled import default_maze_path
from workbench.files.terminal import TerminalSafeWriter
from workbench.labs.store.store import StoreError, resolve_db
from workbench.wire.settings import AppSettings

from . import algorithms as algorithms_cmd
from . import grade as grade_cmd
from . import instructor as instructor_cmd
from . import labs as labs_cmd
from . import maze as maze_cmd
from . import picture as picture_cmd
from . import run as run_cmd
from . import serve as serve_cmd
from . import signoff as signoff_cmd
from . import ssh as ssh_cmd
from . import store as store_cmd
from . import viple_client as viple_client_cmd
from . import viple_program as viple_program_cmd
from . import web as web_cmd
from .common import (
    db_option,
    error,
    new_runs_dir,
    record_quota_options,
    report_ms_option,
    runs_home,
)


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="workbench",
        description="VIPLE Maze Lab Workbench: maze simulator and lab workbench for ASU VIPLE.",
        # a command's own options (``run --record``) would otherwise be read as shortened
        # forms of the app's (``--record-dir``, ``--record-cap``)
        allow_abbrev=False,
    )
    parser.add_argument("--version", action="version", version=f"workbench {__version__}")
    parser.add_argument("--maze", help="maze file to open (default: the bundled Unity maze)")
    parser.add_argument("--profile", help="unity, web or erobotic (default: the maze's own)")
    parser.add_argument("--seed", type=int, default=0, help="noise seed (default 0)")
    parser.add_argument("--noise", help="off, low or realistic (default: the profile's)")
    parser.add_argument("--unicode", action="store_true", help="draw the maze with Unicode lines")
    parser.add_argument(
        "--tcp-port",
        type=int,
        default=1350,
        help="VIPLE (Unity-simulator role) connects here on localhost; 0 turns it off "
        "(default 1350)",
    )
    parser.add_argument(
        "--ws-url", help="connect to VIPLE's WebSocket server too (Web-Simulator role)"
    )
    parser.add_argument(
        "--ws-when-asked",
        action="store_true",
        help="with --ws-url: connect only when a WebSocket lab exercise is set up or v is "
        "pressed, not from the start",
    )
    parser.add_argument(
        "--record-dir",
        help=f"keep each run's record here for replay (default: a new folder under {runs_home()})",
    )
    parser.add_argument(
        "--student",
        help="who does the labs (default: asked at start, the login name filled in)",
    )
    parser.add_argument("--partner", default="", help="the student's lab partner, if any")
    parser.add_argument(
        "--ask-partner",
        action="store_true",
        help="with --student: still ask for the partner at start (the name stays as given)",
    )
    parser.add_argument(
        "--role",
        default="student",
        choices=("student", "instructor"),
        help="shown beside the name (default student)",
    )
    parser.add_argument(
        "--connect-hint",
        default="",
        help="how VIPLE reaches this app from elsewhere, shown at start and in the help "
        "(the SSH server sets it)",
    )
    parser.add_argument(
        "--data-dir",
        help="where lab progress and sign-offs are kept (default: $WORKBENCH_DATA "
        "or the user data folder)",
    )
    report_ms_option(parser)
    record_quota_options(parser)
    db_option(parser, top=True)
    parser.add_argument(
        "--workspace",
        metavar="DIR",
        help="open and save files only in DIR and the bundled mazes, labs and starters "
        "(the SSH server gives each student one; made if missing)",
    )
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    maze_cmd.register(sub)
    algorithms_cmd.register(sub)
    run_cmd.register(sub)
    picture_cmd.register(sub)
    grade_cmd.register(sub)
    viple_program_cmd.register(sub)
    labs_cmd.register(sub)
    serve_cmd.register(sub)
    viple_client_cmd.register(sub)
    instructor_cmd.register(sub)
    signoff_cmd.register(sub)
    ssh_cmd.register(sub)
    web_cmd.register(sub)
    store_cmd.register(sub)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    if args.command is None:
        return open_app(args)
    # whatever a command prints (names, labels, evidence read from files and stores) is
    # printed with its control characters escaped: none of it acts on the terminal
    shown, sys.stdout = sys.stdout, cast(TextIO, TerminalSafeWriter(sys.stdout))
    try:
        return int(args.func(args) or 0)
    except KeyboardInterrupt:
        print("interrupted", file=sys.stderr)
        return 130
    except BrokenPipeError:
        # the reader went away (e.g. `| head`): stop quietly, as other command-line tools do
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 141
    finally:
        sys.stdout = shown


def open_app(args: argparse.Namespace) -> int:
    """Without a command: the workbench app on the chosen (or bundled default) maze.

    Bad arguments are reported before the app starts (exit 2). Without a terminal (output
    piped, no Textual driver set) the maze and its check are printed instead.
    """
    from workbench.tui.app import AppSetupError, make_app

    try:
        db = resolve_db(args.db)
    except StoreError as exc:
        error(str(exc))
        return 2
    try:
        app = make_app(app_settings(args, db))
    except AppSetupError as exc:
        error(str(exc))
        return 2
    terminal = sys.stdin.isatty() and sys.stdout.isatty()
    if not terminal and not os.environ.get("TEXTUAL_DRIVER"):
        print("workbench: not a terminal, so no app: here is the maze", file=sys.stderr)
        return demo(args)
    app.holds_process = True
    app.run()
    return app.return_code or 0


def app_settings(args: argparse.Namespace, db: str | None) -> AppSettings:
    """The app's settings from the command line's options (``db``: the course database the
    options or the environment name)."""
    return AppSettings(
        maze_path=Path(args.maze) if args.maze else None,
        profile=args.profile,
        seed=args.seed,
        noise=args.noise,
        report_ms=args.report_ms,
        unicode=args.unicode,
        tcp_port=args.tcp_port or None,
        ws_url=args.ws_url,
        ws_at_start=not args.ws_when_asked,
        record_dir=Path(args.record_dir or new_runs_dir()),
        record_cap=args.record_cap,
        runs_quota=args.runs_quota,
        runs_counted=_counted_runs(args),
        student=args.student,
        partner=args.partner,
        data_dir=Path(args.data_dir) if args.data_dir else None,
        role=args.role,
        ask_names=not args.student or args.ask_partner,
        # over SSH (OpenSSH's ForceCommand, say) the login name is the student's
        student_fixed=bool(args.student) or "SSH_CONNECTION" in os.environ,
        connect_hint=args.connect_hint,
        workspace=Path(args.workspace) if args.workspace else None,
        db=db,
    )


def _counted_runs(args: argparse.Namespace) -> Path | None:
    """The folder the runs quota counts: the workspace's ``runs``, the app's own runs folder,
    or (None) just the record folder given."""
    if args.workspace:
        return Path(args.workspace) / "runs"
    return None if args.record_dir else Path(runs_home())


def demo(args: argparse.Namespace) -> int:
    """Without a command: show the chosen (or bundled default) maze and its check."""
    path = args.maze or str(default_maze_path())
    return maze_cmd.show_and_check(path)
