"""The options both doors' servers take (``serve-ssh`` and ``serve-web``), where they mean the
same: the sessions in all, idle time, memory, terminal size, app logs, password locks, the fork
server."""

from __future__ import annotations

import argparse

from workbench.door.limits import SessionLimits
from workbench.door.serverlog import SERVER_LOG_SIZE

from .common import size


def door_options(parser: argparse.ArgumentParser) -> None:
    """The options of a door's server that mean the same for both doors."""
    parser.add_argument(
        "--max-sessions", type=int, default=60, help="sessions in all (default 60)"
    )
    parser.add_argument(
        "--idle-timeout", type=float, default=7200,
        help="seconds without input before a session is closed (default 7200)",
    )  # fmt: skip
    parser.add_argument(
        "--server-memory", type=int, default=SessionLimits.server_memory, metavar="MIB",
        help="the server process's own memory, in MiB, past which it takes no new connections, "
        "channels or sessions while the live ones go on (default 1024; 0: not watched)",
    )  # fmt: skip
    parser.add_argument(
        "--server-log-size", type=size, default=SERVER_LOG_SIZE, metavar="SIZE",
        help="the largest the server's log (ssh.log, web.log) grows; a full one is kept as "
        ".log.1 and a new one begun (e.g. 20M; 0: no limit; default 20 MB)",
    )  # fmt: skip
    parser.add_argument(
        "--max-terminal", default="500x200", metavar="COLSxROWS",
        help="the largest terminal an app is given; larger ones are clamped (default 500x200)",
    )  # fmt: skip
    parser.add_argument(
        "--app-memory", type=int, default=512, metavar="MIB",
        help="memory each session's app may use, in MiB; an app past it is ended with a "
        "message (default 512; 0: no cap)",
    )  # fmt: skip
    parser.add_argument(
        "--app-log-size", type=size, default=SessionLimits.app_log, metavar="SIZE",
        help="the largest one session's error log grows; a full one is kept as .log.1 and a "
        "new one begun (e.g. 1M; 0: no limit; default 1 MB)",
    )  # fmt: skip
    parser.add_argument(
        "--user-logs-quota", type=size, default=SessionLimits.user_logs, metavar="SIZE",
        help="the most one user's error logs (<data-dir>/logs/USER) may take; the oldest are "
        "removed at a session's start (0: no limit; default 20 MB)",
    )  # fmt: skip
    parser.add_argument(
        "--password-lock-after", type=int, default=10,
        help="wrong passwords for one account before its passwords are locked (default 10)",
    )  # fmt: skip
    parser.add_argument(
        "--password-lock-for", type=float, default=900,
        help="seconds an account takes no passwords once locked; keys still work (default 900)",
    )  # fmt: skip
    parser.add_argument(
        "--no-fork-server", action="store_true",
        help="start each session's app as a new Python process instead of forking it from a "
        "fork server that has the app imported (slower to start, more memory)",
    )  # fmt: skip
