"""``workbench serve-web``: the browser door, the same served workbench in a web page."""

from __future__ import annotations

import argparse
import math
import os
from pathlib import Path

from workbench.control.recording import RecordQuota
from workbench.door.limits import SessionLimits
from workbench.files.workspace_files import UploadLimits
from workbench.labs.store.database import ENV_DB
from workbench.labs.store.store import StoreError, resolve_data_dir, resolve_db

from .common import db_option, record_quota_options, upload_options
from .doors import door_options, login_policy, spares_problem
from .ssh import (
    WORKBENCH_APP,
    Door,
    data_dir_option,
    fail,
    parse_terminal,
    prepare_course_store,
)


def register(sub: argparse._SubParsersAction) -> None:
    serve = sub.add_parser(
        "serve-web",
        help="the browser door: every student's workbench in a web page, logged in with the "
        "lab server's accounts",
        description="Serve the workbench in a web page: users from the users file of "
        "'workbench ssh add-user' log in with their password (or through a sign-on proxy "
        "that names them, --user-header) and each gets their own workbench. See docs/web.md.",
    )
    serve.add_argument("--port", type=int, default=8080, help="HTTP(S) port (default 8080)")
    serve.add_argument("--bind", default="", help="address to listen on (default: all)")
    serve.add_argument("--users", help="users file (default <data-dir>/ssh-users.yaml)")
    data_dir_option(serve)
    db_option(serve)
    serve.add_argument(
        "--port-range", default="42000-42999",
        help="VIPLE ports for sessions, two each (default 42000-42999; keep it apart from "
        "serve-ssh's on the same machine)",
    )  # fmt: skip
    serve.add_argument("--tls-cert", help="the server's certificate chain (PEM), for https")
    serve.add_argument("--tls-key", help="the certificate's private key (PEM)")
    serve.add_argument(
        "--user-header", default="", metavar="HEADER",
        help="log users in by this header, set by an authenticating proxy in front (e.g. "
        "X-Forwarded-User); passwords are then not taken (needs --trusted-proxy)",
    )  # fmt: skip
    serve.add_argument(
        "--trusted-proxy", default="", metavar="FROM",
        help="the proxies' or load balancers' addresses or networks (comma-separated) whose "
        "X-Forwarded-For, X-Forwarded-Proto and --user-header are believed (default: none)",
    )  # fmt: skip
    serve.add_argument(
        "--reattach-grace", type=float, default=60, metavar="SECONDS",
        help="seconds a student's workbench waits for its page to come back after a reload or "
        "a lost connection (default 60)",
    )  # fmt: skip
    serve.add_argument(
        "--login-hours", type=float, default=12,
        help="hours a browser's login lasts (default 12)",
    )  # fmt: skip
    door_options(serve)
    record_quota_options(serve)
    upload_options(serve)
    serve.set_defaults(func=cmd_serve_web)


def cmd_serve_web(args: argparse.Namespace) -> int:
    from workbench.door.networks import parse_networks
    from workbench.door.ports import parse_range
    from workbench.door.serverlog import setup_logging
    from workbench.door.users import UsersFileError
    from workbench.web.config import WebConfig
    from workbench.web.server import WebServer

    command = "serve-web"
    if not 0 <= args.port <= 65535:
        return fail(command, f"--port {args.port} is not a port: use 1-65535 (default 8080)")
    try:
        port_range = parse_range(args.port_range)
        proxies = parse_networks(args.trusted_proxy) if args.trusted_proxy else ()
        columns, rows = parse_terminal(args.max_terminal)
    except ValueError as exc:
        return fail(command, f"{exc} (in --port-range, --trusted-proxy or --max-terminal)")
    if bool(args.tls_cert) != bool(args.tls_key):
        return fail(command, "give --tls-cert and --tls-key together (or neither, for http)")
    for given in (args.tls_cert, args.tls_key):
        if given and not Path(given).is_file():
            return fail(command, f"{given}: no such file (--tls-cert/--tls-key)")
    if args.user_header and not proxies:
        return fail(
            command,
            f"--user-header {args.user_header} needs --trusted-proxy: the addresses of the "
            "proxy that sets it (the header from anywhere else is refused)",
        )
    numbers = (args.reattach_grace, args.login_hours, args.idle_timeout)
    if (
        not all(math.isfinite(x) and x > 0 for x in numbers)
        or min(args.max_sessions, args.max_per_user) < 1
    ):
        return fail(
            command,
            "--reattach-grace, --login-hours, --idle-timeout, --max-sessions and --max-per-user "
            "must be > 0",
        )
    if (problem := spares_problem(args.spare_apps)) is not None:
        return fail(command, problem)
    if args.app_memory < 0 or 0 < args.app_memory < 64:
        return fail(command, f"--app-memory {args.app_memory}: give at least 64 (MiB) or 0")
    logins = login_policy(args)
    if isinstance(logins, str):
        return fail(command, logins)
    data_dir = resolve_data_dir(args.data_dir)
    try:
        db = resolve_db(args.db)
    except StoreError as exc:
        return fail(command, str(exc))
    if db:
        problem = prepare_course_store(data_dir, db)
        if problem:
            return fail(command, f"{problem}\nthe server did not start")
        os.environ[ENV_DB] = db
    config = WebConfig(
        data_dir=data_dir,
        port=args.port,
        bind=args.bind,
        users_file=Path(args.users) if args.users else None,
        port_range=port_range,
        limits=SessionLimits(
            per_user=args.max_per_user,
            total=args.max_sessions,
            idle_timeout=args.idle_timeout,
            max_columns=columns,
            max_rows=rows,
            app_memory=args.app_memory,
            app_log=args.app_log_size or 0,
            user_logs=args.user_logs_quota or 0,
            server_memory=args.server_memory,
        ),
        logins=logins,
        fork_server=not args.no_fork_server,
        spare_apps=args.spare_apps,
        reattach_grace=args.reattach_grace,
        login_lifetime=args.login_hours * 3600,
        tls_cert=Path(args.tls_cert) if args.tls_cert else None,
        tls_key=Path(args.tls_key) if args.tls_key else None,
        user_header=args.user_header,
        trusted_proxies=proxies,
        app=WORKBENCH_APP,
        record_quota=RecordQuota(args.record_cap, args.runs_quota),
        uploads=UploadLimits(args.upload_cap or 0, args.workspace_quota or 0, args.workspace_files),
        db=db,
    )
    try:
        log_path = setup_logging(
            data_dir, size=args.server_log_size or 0, file_name="web.log",
            also=("workbench.web",),
        )  # fmt: skip
        server = WebServer(config)
    except UsersFileError as exc:
        return fail(command, f"{exc}\nthe server did not start")
    except OSError as exc:
        return fail(command, f"cannot use the data folder {data_dir}: {exc}")
    door = Door(command, "workbench.web", "--role student")
    return door.serve(server, log_path, data_dir, db, args.port)
