"""``workbench serve-ssh`` (the SSH lab server) and ``workbench ssh`` (its users)."""

from __future__ import annotations

import argparse
import asyncio
import getpass
import logging
import math
import os
import signal
import sys
from dataclasses import dataclass
from pathlib import Path

from workbench.control.recording import RecordQuota
from workbench.door.appproc import AppEntry
from workbench.door.limits import SessionLimits
from workbench.files.workspace_files import UploadLimits
from workbench.labs.store.database import ENV_DB, redact
from workbench.labs.store.store import (
    DB_NAME,
    Store,
    StoreError,
    StoreUnavailable,
    resolve_data_dir,
    resolve_db,
)

from .common import db_option, record_quota_options, upload_options
from .doors import door_options, login_policy, spares_problem

#: the app every SSH session runs, given the session's settings as JSON (see
#: :mod:`workbench.cli.served`): this Python's ``-m workbench.cli.served``, or forked from the
#: fork server as :func:`workbench.cli.served.main` with the app's modules imported beforehand
#: and its first screen's common work done once (:func:`workbench.tui.app.warm_up`)
WORKBENCH_APP = AppEntry(
    command=(sys.executable, "-m", "workbench.cli.served"),
    main="workbench.cli.served:main",
    preload=("workbench.tui.app:warm_up",),
    spare="workbench.cli.served:spare",
)


def register(sub: argparse._SubParsersAction) -> None:
    serve = sub.add_parser(
        "serve-ssh",
        help="the SSH lab server: every student's workbench over SSH, each with own VIPLE ports",
        description="Serve the workbench over SSH: users from the users file log in with a key "
        "or a password and each session runs its own workbench with its own VIPLE ports. "
        "See docs/ssh.md.",
    )
    serve.add_argument("--port", type=int, default=2222, help="SSH port (default 2222)")
    serve.add_argument("--bind", default="", help="address to listen on (default: all)")
    serve.add_argument(
        "--proxy-protocol", metavar="FROM", default="",
        help="connections from FROM (the load balancer's addresses or networks, "
        "comma-separated) start with a PROXY protocol header (HAProxy's send-proxy-v2) naming "
        "the student's address, which the login limits and the log then use (default: none)",
    )  # fmt: skip
    serve.add_argument(
        "--host-key", help="the server's private key (default <data-dir>/ssh_host_ed25519_key, "
        "made on first start)"
    )  # fmt: skip
    serve.add_argument("--users", help="users file (default <data-dir>/ssh-users.yaml)")
    data_dir_option(serve)
    db_option(serve)
    serve.add_argument(
        "--port-range", default="41000-41999",
        help="VIPLE ports for sessions, two each (default 41000-41999)",
    )  # fmt: skip
    serve.add_argument(
        "--public-host", default="",
        help="the server's name as students type it, for the forwarding command shown in the "
        "app (default: this machine's full name)",
    )  # fmt: skip
    serve.add_argument(
        "--max-connections-per-user", type=int, default=10,
        help="connections one user may hold logged in, with or without a session (default 10)",
    )  # fmt: skip
    serve.add_argument(
        "--max-channels-per-connection", type=int, default=SessionLimits.channels_per_connection,
        metavar="N",
        help="channels one connection may hold open at once: sessions, file transfers and "
        "forwards (default 10)",
    )  # fmt: skip
    serve.add_argument(
        "--channel-grace", type=float, default=SessionLimits.channel_grace, metavar="SECONDS",
        help="seconds a session channel has to ask for a terminal, a command or a file "
        "transfer before it is closed (default 10)",
    )  # fmt: skip
    record_quota_options(serve)
    upload_options(serve)
    door_options(serve)
    serve.set_defaults(func=cmd_serve)

    users = sub.add_parser("ssh", help="users of the SSH lab server")
    inner = users.add_subparsers(dest="ssh_command", metavar="ACTION", required=True)
    add = inner.add_parser(
        "add-user", help="add a user or change one (role, more keys, a new password)"
    )
    add.add_argument("name", help="the login name, also the student's name in the labs")
    add.add_argument("--role", required=True, choices=("student", "instructor"))
    add.add_argument(
        "--key", action="append", default=[], metavar="PUBFILE",
        help="a public key file (e.g. id_ed25519.pub) whose keys may log in; repeatable",
    )  # fmt: skip
    add.add_argument(
        "--password", action="store_true",
        help="set a password (asked twice; without a terminal: read from standard input)",
    )  # fmt: skip
    add.add_argument("--users", help="users file (default <data-dir>/ssh-users.yaml)")
    data_dir_option(add)
    add.set_defaults(func=cmd_add_user)

    ls = inner.add_parser("list-users", help="list the users, their roles and credentials")
    ls.add_argument("--users", help="users file (default <data-dir>/ssh-users.yaml)")
    data_dir_option(ls)
    ls.set_defaults(func=cmd_list_users)


def data_dir_option(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "--data-dir",
        help="the workbench's data folder (default: $WORKBENCH_DATA, else the user data folder)",
    )


def fail(command: str, message: str) -> int:
    print(f"workbench {command}: {message}", file=sys.stderr)
    return 2


def _users_file(args: argparse.Namespace) -> Path:
    from workbench.door.users import users_path

    return Path(args.users) if args.users else users_path(resolve_data_dir(args.data_dir))


# -- users --------------------------------------------------------------------------------------
def read_new_password() -> str:
    """Asked twice on a terminal; without one, the first line of standard input (for scripts;
    a second line, if given, must repeat it)."""
    from workbench.door.passwords import MIN_PASSWORD, PasswordError, check_password

    if not sys.stdin.isatty():
        lines = sys.stdin.read().splitlines()
        if not lines:
            raise PasswordError("no password on standard input")
        if len(lines) > 1 and lines[1] and lines[1] != lines[0]:
            raise PasswordError("the two passwords on standard input differ")
        return check_password(lines[0])
    print(f"Choose a password of at least {MIN_PASSWORD} characters.", file=sys.stderr)
    first = check_password(getpass.getpass("Password: "))
    if getpass.getpass("Password again: ") != first:
        raise PasswordError("the two passwords differ; nothing was changed")
    return first


def cmd_add_user(args: argparse.Namespace) -> int:
    from workbench.door.passwords import PasswordError, hash_password
    from workbench.door.users import UsersFileError, add_user, parse_public_key

    path = _users_file(args)
    keys: list[str] = []
    for name in args.key:
        try:
            lines = Path(name).expanduser().read_text(encoding="utf-8").splitlines()
        except (OSError, UnicodeDecodeError) as exc:
            return fail("ssh add-user", f"cannot read the key file {name}: {exc}")
        found = [ln.strip() for ln in lines if ln.strip() and not ln.lstrip().startswith("#")]
        if not found:
            return fail("ssh add-user", f"{name} has no public key in it")
        for number, line in enumerate(found, 1):
            try:
                parse_public_key(line)
            except ValueError as exc:
                hint = " (give the .pub file, not the private key)" if "PRIVATE" in line else ""
                return fail("ssh add-user", f"{name}: key {number}: {exc}{hint}")
            keys.append(line)
    try:
        password = hash_password(read_new_password()) if args.password else None
        user = add_user(path, args.name, args.role, keys, password)
    except (PasswordError, UsersFileError, EOFError) as exc:
        return fail("ssh add-user", str(exc) or "no password given")
    except OSError as exc:
        return fail("ssh add-user", f"cannot write {path}: {exc.strerror}")
    what = [f"{len(user.keys)} key{'s' if len(user.keys) != 1 else ''}"]
    if user.password:
        what.append("a password")
    print(f"{user.name} ({user.role}) can log in with {' and '.join(what)}; saved in {path}")
    return 0


def cmd_list_users(args: argparse.Namespace) -> int:
    from workbench.door.users import UsersFileError, load_users

    path = _users_file(args)
    try:
        users = load_users(path)
    except UsersFileError as exc:
        return fail("ssh list-users", str(exc))
    if not users:
        print(f"no users in {path} (add one: workbench ssh add-user NAME --role student --key "
              "FILE.pub)")  # fmt: skip
        return 0
    width = max(len(n) for n in users)
    for user in sorted(users.values(), key=lambda u: u.name):
        parts = user.fingerprints() or ["no keys"]
        if user.password:
            parts.append("password")
        print(f"{user.name:<{width}}  {user.role:<10}  {', '.join(parts)}")
    return 0


# -- the server -------------------------------------------------------------------------------
def cmd_serve(args: argparse.Namespace) -> int:
    from workbench.door.ports import parse_range
    from workbench.door.serverlog import setup_logging
    from workbench.door.users import UsersFileError
    from workbench.ssh.hostkey import HostKeyError
    from workbench.ssh.server import LabServer, ServerConfig

    if not 0 <= args.port <= 65535:
        return fail(
            "serve-ssh", f"--port {args.port} is not a port: use 1-65535 (default 2222; 0: any)"
        )
    try:
        port_range = parse_range(args.port_range)
    except ValueError as exc:
        return fail("serve-ssh", f"--port-range {exc}")
    if port_range[0] <= args.port <= port_range[1]:
        return fail(
            "serve-ssh",
            f"--port {args.port} lies inside --port-range {args.port_range}, which is kept for "
            "the sessions' VIPLE ports: choose a port outside it",
        )
    from workbench.door.networks import parse_networks

    try:
        proxy_from = parse_networks(args.proxy_protocol) if args.proxy_protocol else ()
    except ValueError as exc:
        return fail("serve-ssh", f"--proxy-protocol {exc}")
    if args.max_per_user < 1 or args.max_sessions < 1 or not args.idle_timeout > 0:
        return fail("serve-ssh", "--max-per-user, --max-sessions and --idle-timeout must be > 0")
    if (problem := spares_problem(args.spare_apps)) is not None:
        return fail("serve-ssh", problem)
    if args.max_connections_per_user < 1:
        return fail(
            "serve-ssh",
            f"--max-connections-per-user {args.max_connections_per_user}: must be at least 1 "
            "(default 10)",
        )
    if args.max_channels_per_connection < 1:
        return fail(
            "serve-ssh",
            f"--max-channels-per-connection {args.max_channels_per_connection}: must be at "
            "least 1 (default 10)",
        )
    if not (math.isfinite(args.channel_grace) and args.channel_grace > 0):
        return fail(
            "serve-ssh", f"--channel-grace {args.channel_grace:g}: must be > 0 (default 10)"
        )
    if args.server_memory < 0 or 0 < args.server_memory < 128:
        return fail(
            "serve-ssh",
            f"--server-memory {args.server_memory}: give at least 128 (MiB; the server needs "
            "about 60) or 0 to leave it unwatched (default 1024)",
        )
    try:
        columns, rows = parse_terminal(args.max_terminal)
    except ValueError as exc:
        return fail("serve-ssh", f"--max-terminal {args.max_terminal!r}: {exc}")
    if args.app_memory < 0 or 0 < args.app_memory < 64:
        return fail(
            "serve-ssh",
            f"--app-memory {args.app_memory}: give at least 64 (MiB; an app needs about 50) or "
            "0 for no cap (default 512)",
        )
    logins = login_policy(args)
    if isinstance(logins, str):
        return fail("serve-ssh", logins)
    data_dir = resolve_data_dir(args.data_dir)
    try:
        db = resolve_db(args.db)
    except StoreError as exc:
        return fail("serve-ssh", str(exc))
    if db:
        problem = prepare_course_store(data_dir, db)
        if problem:
            return fail("serve-ssh", f"{problem}\nthe server did not start")
        os.environ[ENV_DB] = db  # every session's app inherits it (never on a command line)
    config = ServerConfig(
        data_dir=data_dir,
        port=args.port,
        bind=args.bind,
        host_key=Path(args.host_key) if args.host_key else None,
        users_file=Path(args.users) if args.users else None,
        port_range=port_range,
        public_host=args.public_host,
        limits=SessionLimits(
            args.max_per_user,
            args.max_sessions,
            args.idle_timeout,
            connections_per_user=args.max_connections_per_user,
            max_columns=columns,
            max_rows=rows,
            app_memory=args.app_memory,
            app_log=args.app_log_size or 0,
            user_logs=args.user_logs_quota or 0,
            channels_per_connection=args.max_channels_per_connection,
            channel_grace=args.channel_grace,
            server_memory=args.server_memory,
        ),
        logins=logins,
        fork_server=not args.no_fork_server,
        spare_apps=args.spare_apps,
        app=WORKBENCH_APP,
        record_quota=RecordQuota(args.record_cap, args.runs_quota),
        uploads=UploadLimits(args.upload_cap or 0, args.workspace_quota or 0, args.workspace_files),
        db=db,
        proxy_from=proxy_from,
    )
    try:
        log_path = setup_logging(data_dir, size=args.server_log_size or 0)
        server = LabServer(config)
    except (UsersFileError, HostKeyError) as exc:
        return fail("serve-ssh", f"{exc}\nthe server did not start")
    except OSError as exc:
        return fail("serve-ssh", f"cannot use the data folder {data_dir}: {exc}")
    door = Door("serve-ssh", "workbench.ssh", "--role student --key FILE.pub")
    return door.serve(server, log_path, data_dir, db, args.port)


@dataclass(frozen=True)
class Door:
    """What a door's command says as its server starts: its name, its log, and how to add
    the first user."""

    command: str
    logger: str
    add_user: str

    def serve(self, server, log_path: Path, data_dir: Path, db: str | None, port: int) -> int:
        """Say the start (no users yet, where the log goes, which course store) and serve
        until stopped; the exit code."""
        if not server.users.users:
            print(
                f"workbench {self.command}: no users yet in {server.users.path}: add one with "
                f"'workbench ssh add-user NAME {self.add_user}'",
                file=sys.stderr,
            )
        print(f"workbench {self.command}: logging to {log_path}", file=sys.stderr)
        logging.getLogger(self.logger).info("course store: %s", store_words(data_dir, db))
        try:
            return asyncio.run(serve_until_stopped(server))
        except OSError as exc:
            return fail(self.command, f"cannot listen on port {port}: {exc.strerror or exc}")


def parse_terminal(text: str) -> tuple[int, int]:
    """``"500x200"`` as ``(500, 200)``; ValueError saying what is wrong."""
    columns, sep, rows = text.lower().partition("x")
    if not sep or not columns.strip().isdigit() or not rows.strip().isdigit():
        raise ValueError("write it as COLUMNSxROWS, e.g. 500x200")
    size = int(columns), int(rows)
    if size[0] < 80 or size[1] < 24:
        raise ValueError("the app needs at least 80x24")
    return size


def store_words(data_dir: Path, db: str | None) -> str:
    """Which store the sessions keep students' work in: the course database's URL without its
    password, or the SQLite file in the data folder."""
    if db:
        return f"the course database {redact(db)}"
    return f"SQLite in the data folder, {data_dir / DB_NAME}"


def prepare_course_store(data_dir: Path, db: str) -> str:
    """Bring the course database's schema up to date once, before any session opens it.
    A server that is down only warns: the apps keep students' work until it is back."""
    try:
        Store.open(data_dir, db=db).close()
    except StoreUnavailable as exc:
        print(
            f"workbench serve-ssh: {exc}: serving anyway; the apps keep students' progress "
            "until the database is back",
            file=sys.stderr,
        )
    except StoreError as exc:
        return str(exc)
    return ""


async def serve_until_stopped(server) -> int:
    stop = asyncio.Event()
    loop = asyncio.get_running_loop()
    for sig in (signal.SIGINT, signal.SIGTERM):
        loop.add_signal_handler(sig, stop.set)
    await server.start()
    try:
        await stop.wait()
    finally:
        await server.close()
    return 0
