"""The options both doors' servers take (``serve-ssh`` and ``serve-web``), where they mean the
same: the sessions in all and per user, idle time, memory, terminal size, app logs, the rules
for connections not logged in yet, password locks, the fork server."""

from __future__ import annotations

import argparse
import math

from workbench.door.limits import SessionLimits
from workbench.door.logins import LoginPolicy
from workbench.door.serverlog import SERVER_LOG_SIZE
from workbench.door.spares import MAX_SPARES

from .common import size


def door_options(parser: argparse.ArgumentParser) -> None:
    """The options of a door's server that mean the same for both doors."""
    parser.add_argument("--max-sessions", type=int, default=60, help="sessions in all (default 60)")
    parser.add_argument(
        "--max-per-user", type=int, default=2,
        help="workbench sessions one user may have open at once, counted over every server "
        "of either door serving the same data folder (default 2)",
    )  # fmt: skip
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
        "--login-timeout", type=float, default=30,
        help="seconds a connection has to log in (default 30)",
    )  # fmt: skip
    parser.add_argument(
        "--max-unauthenticated", type=int, default=100,
        help="connections not logged in yet, in all (default 100)",
    )  # fmt: skip
    parser.add_argument(
        "--max-unauthenticated-per-address", type=int, default=10,
        help="connections not logged in yet from one address (default 10)",
    )  # fmt: skip
    parser.add_argument(
        "--unauthenticated-start", type=int, default=50,
        help="from this many connections not logged in yet, new ones are dropped at random, "
        "more often the nearer --max-unauthenticated (default 50)",
    )  # fmt: skip
    parser.add_argument(
        "--unauthenticated-grace", type=float, default=5,
        help="seconds a connection not logged in keeps its place for sure; past them it is "
        "closed to make room when a new connection finds the places full or would be dropped "
        "at random, from the address holding the most places first (default 5; at or above "
        "--login-timeout: never)",
    )  # fmt: skip
    parser.add_argument(
        "--penalty-min", type=float, default=90,
        help="seconds of places at the login held by connections that went without logging "
        "in, beyond what time has paid back, before their address (IPv6: /64) is refused "
        "(default 90)",
    )  # fmt: skip
    parser.add_argument(
        "--penalty-max", type=float, default=600,
        help="the longest an address is refused for that (default 600; 0: no penalties)",
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
        "--spare-apps", type=int, default=0, metavar="N",
        help="keep N students' apps started ahead of their sessions, each waiting at the names "
        "dialog, so that a class logging in at once sees its first screens sooner (each spare "
        "holds an app's memory while it waits; default 0: each app starts with its session)",
    )  # fmt: skip
    parser.add_argument(
        "--no-fork-server", action="store_true",
        help="start each session's app as a new Python process instead of forking it from a "
        "fork server that has the app imported (slower to start, more memory)",
    )  # fmt: skip


def spares_problem(count: int) -> str | None:
    """What is wrong with ``--spare-apps COUNT`` (None: nothing)."""
    if 0 <= count <= MAX_SPARES:
        return None
    return f"--spare-apps {count}: give 0 (no spares) to {MAX_SPARES}"


def login_policy(args: argparse.Namespace) -> LoginPolicy | str:
    """The login rules the options give, or what is wrong with them."""
    penalties = (args.penalty_min, args.penalty_max)
    if not all(math.isfinite(x) and x >= 0 for x in penalties) or args.unauthenticated_start < 1:
        return (
            "--penalty-min and --penalty-max must be 0 or more (0: no penalties), and "
            "--unauthenticated-start at least 1"
        )
    login_numbers = (
        args.login_timeout,
        args.unauthenticated_grace,
        args.max_unauthenticated,
        args.max_unauthenticated_per_address,
        args.password_lock_after,
        args.password_lock_for,
    )
    if not all(math.isfinite(x) and x > 0 for x in login_numbers):
        return (
            "--login-timeout, --unauthenticated-grace, --max-unauthenticated, "
            "--max-unauthenticated-per-address, --password-lock-after and --password-lock-for "
            "must be > 0"
        )
    return LoginPolicy(
        login_timeout=args.login_timeout,
        max_unauthenticated=args.max_unauthenticated,
        max_unauthenticated_per_address=args.max_unauthenticated_per_address,
        lock_after=args.password_lock_after,
        lock_for=args.password_lock_for,
        unauthenticated_start=args.unauthenticated_start,
        unauthenticated_grace=args.unauthenticated_grace,
        penalty_least=args.penalty_min,
        penalty_longest=args.penalty_max,
    )
