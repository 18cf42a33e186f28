"""The browser door's server: HTTP and WebSocket (aiohttp), logins, one app per student.

Routes: ``/login`` (the form, and its POST), ``/logout``, ``/`` (the terminal page), ``/ws``
(the page's WebSocket), ``/files`` (a folder's listing, and uploads) and ``/files/PATH``
(downloads), ``/static/`` (xterm.js and our page's script and styles). Every refusal of what a
browser (or something posing as one) sent is answered plainly and said in one log line, the
repeatable ones at most once per 10 s.
"""

from __future__ import annotations

import asyncio
import json
import logging
import ssl
import time
from collections import Counter
from pathlib import Path
from typing import Any
from urllib.parse import urlsplit

from aiohttp import WSMsgType, web

from workbench.door.appproc import AppProcess, AppSpec, app_env, keep_spares
from workbench.door.checking import PasswordDesk
from workbench.door.course_files import CourseWorkspaces, bring_workspace
from workbench.door.forkserver import ForkServer, ForkServerError
from workbench.door.leases import Lease, SessionLeases
from workbench.door.limits import describe_duration, describe_memory
from workbench.door.logins import ConnectionGate, LoginGuard, QuietLog
from workbench.door.memory import SHORT_OF_MEMORY, MemoryWatch
from workbench.door.ports import PoolExhausted, PortPool
from workbench.door.serverlog import shown
from workbench.door.users import UsersFile
from workbench.door.workers import FILES, in_pool
from workbench.files.workspace import workspace_folder

from . import transfer
from .config import WebConfig
from .cookies import (
    CSRF_COOKIE,
    LOGINS_FOLDER,
    SESSION_COOKIE,
    Login,
    Logins,
    new_token,
    same_token,
)
from .gate import RequestGate
from .pages import login_page, terminal_page
from .proxy import Origin, header_login, origin_of
from .relay import Notice, StudentApp, background

log = logging.getLogger("workbench.web")
#: the login a sign-on header opened while this request was handled, for its cookie
NEW_LOGIN = web.RequestKey("new_login", str)

STATIC = Path(__file__).resolve().parent / "static"
#: the page may load and connect to this server only; no frames, no inline script (styles
#: inline are allowed: xterm.js sets its theme's colours in a style element of its own)
SECURITY_HEADERS = {
    "Content-Security-Policy": (
        "default-src 'self'; script-src 'self'; style-src 'self' 'unsafe-inline'; "
        "img-src 'self' data:; connect-src 'self'; frame-ancestors 'none'; base-uri 'none'; "
        "form-action 'self'"
    ),
    "X-Content-Type-Options": "nosniff",
    "Referrer-Policy": "same-origin",
    "Cache-Control": "no-store",
}
#: the form token a script sends with an upload, when not in the form
FORM_HEADER = "X-Workbench-Form"
#: the largest a terminal is asked to be by a page, before clamping (a page's size is a
#: number of columns and rows; more digits than this is no terminal)
MAX_SIZE_DIGITS = 6
WEB_HINT = (
    "VIPLE: through the browser a VIPLE program file runs here (send it with Files); "
    "VIPLE itself reaches the robot through the SSH door"
)


class WebServer:
    """The running browser door."""

    def __init__(self, config: WebConfig) -> None:
        self.config = config
        assert config.users_file is not None  # __post_init__
        self.users = UsersFile(config.users_file)
        self.guard = LoginGuard(config.logins)
        self.gate: ConnectionGate[object] = ConnectionGate(config.logins)
        self.desk = PasswordDesk(self.users, self.guard, self.gate)
        self.requests = RequestGate(
            self.gate,
            config.logins.login_timeout,
            config.trusted_proxies,
            lambda key, line: self.say_now_and_then(key, "%s", line),
        )
        #: kept in the data folder, so a restart logs no one out
        self.logins = Logins(config.login_lifetime, folder=config.data_dir / LOGINS_FOLDER)
        self.pool = PortPool(*config.port_range)
        self.apps: dict[str, StudentApp] = {}
        #: every door's sessions in this data folder, for the per-user cap
        self.leases = SessionLeases(config.data_dir, "web")
        self.quiet_log = QuietLog()
        self.memory = MemoryWatch(config.limits.server_memory)
        self.forkserver: ForkServer | None = None
        #: with a course database, uploads go on to it (and so to every server of the course)
        self.course_files = CourseWorkspaces(config.data_dir, config.db) if config.db else None
        self.pages_open: Counter[str] = Counter()
        self._runner: web.AppRunner | None = None
        self._site: web.TCPSite | None = None
        self._sweeper: asyncio.Task[None] | None = None
        self._starting: dict[str, asyncio.Task[StudentApp | str]] = {}
        self._closing = False

    # -- start and stop ----------------------------------------------------------------------
    def application(self) -> web.Application:
        config = self.config
        app = web.Application(
            client_max_size=max(config.uploads.file_size, 1 << 20) + (64 << 10),
            middlewares=[self._headers],
        )
        app.add_routes(
            [
                web.get("/", self.index),
                web.get("/favicon.ico", self.no_icon),
                web.get("/login", self.login_form),
                web.post("/login", self.login),
                web.post("/logout", self.logout),
                web.get("/ws", self.websocket),
                web.get("/files", self.list_files),
                web.post("/files", self.upload),
                web.get("/files/{path:.*}", self.download),
                web.static("/static", STATIC, follow_symlinks=False),
            ]
        )
        return app

    @property
    def port(self) -> int:
        assert self._site is not None and self._site._server is not None
        sockets = getattr(self._site._server, "sockets", None) or []
        return int(sockets[0].getsockname()[1])

    async def start(self) -> None:
        config = self.config
        await self._start_forkserver()
        context = None
        if config.tls_cert is not None:
            context = ssl.create_default_context(ssl.Purpose.CLIENT_AUTH)
            context.minimum_version = ssl.TLSVersion.TLSv1_2
            context.load_cert_chain(config.tls_cert, config.tls_key)
        self._runner = web.AppRunner(
            self.application(),
            access_log=None,
            handle_signals=False,
            keepalive_timeout=config.logins.login_timeout,
        )
        await self._runner.setup()
        assert self._runner.server is not None
        self.requests.watch(self._runner.server)
        self._site = web.TCPSite(
            self._runner, config.bind or None, config.port, ssl_context=context
        )
        try:
            await self._site.start()
        except BaseException:
            await self._runner.cleanup()
            if self.forkserver is not None:
                await self.forkserver.close()
            raise
        self._sweeper = asyncio.create_task(self._sweep_idle(), name="web-idle-sweeper")
        how = "https" if context else "http"
        log.info(
            "serving the browser door on %s port %d (%s) for %d users (%s); VIPLE ports "
            "%d-%d; a page may come back within %g s",
            config.bind or "all addresses", self.port, how, len(self.users.users),
            config.users_file, *config.port_range, config.reattach_grace,
        )  # fmt: skip
        if config.user_header:
            log.info(
                "logins by the %s header from %s only (passwords are not taken)",
                config.user_header, ", ".join(map(str, config.trusted_proxies)),
            )  # fmt: skip
        logins = config.logins
        log.info(
            "logins: %g s to send a request; at most %d connections without one (%d per "
            "address); passwords locked for %s after %d failures; %d logins kept from before",
            logins.login_timeout, logins.max_unauthenticated,
            logins.max_unauthenticated_per_address, describe_duration(logins.lock_for),
            logins.lock_after, len(self.logins),
        )  # fmt: skip
        limits = config.limits
        log.info(
            "limits: %d sessions in all, %d per user (over both doors); terminals at most "
            "%dx%d; app memory %s; messages from a page at most %d bytes",
            limits.total, limits.per_user, limits.max_columns, limits.max_rows,
            describe_memory(limits.app_memory) if limits.app_memory else "not capped",
            config.max_message,
        )  # fmt: skip

    async def _start_forkserver(self) -> None:
        config = self.config
        if config.app_command is not None or not config.fork_server:
            log.info("apps start as new processes")
            return
        forkserver = ForkServer(app_env(), config.app.main, config.app.preload)
        try:
            await forkserver.start()
        except ForkServerError as exc:
            log.error("the fork server did not start (%s): apps start as new processes", exc)
            return
        self.forkserver = forkserver
        log.info("apps are forked from a fork server (pid %s)", forkserver.pid)
        keep_spares(forkserver, config.spare_apps, config.app, config.data_dir,
                    config.record_quota, config.uploads)  # fmt: skip

    async def close(self) -> None:
        self._closing = True
        if self._sweeper is not None:
            self._sweeper.cancel()
        apps = list(self.apps.values())
        if apps:
            log.info("stopping: ending %d sessions", len(apps))
        await asyncio.gather(*(self.end(a, "The lab server is stopping.") for a in apps))
        if self._runner is not None:
            await self._runner.cleanup()
        if self.forkserver is not None:
            await self.forkserver.close()
        if self.course_files is not None:
            await self.course_files.close_at_stop(log)

    async def __aenter__(self) -> WebServer:
        await self.start()
        return self

    async def __aexit__(self, *exc: object) -> None:
        await self.close()

    # -- what every answer carries ------------------------------------------------------------
    @web.middleware
    async def _headers(self, request: web.Request, handler: Any) -> web.StreamResponse:
        self.requests.asked(request)
        response = await handler(request)
        if not response.prepared:
            response.headers.update(SECURITY_HEADERS)
        return response

    def say_now_and_then(self, key: str, message: str, *args: object) -> None:
        held = self.quiet_log.due(key)
        if held is None:
            return
        if held:
            message += f" ({held} more like it not logged)"
        log.warning(message, *args)

    def origin(self, request: web.Request) -> Origin:
        peer = request.transport.get_extra_info("peername") if request.transport else None
        address = str(peer[0]) if peer else "unknown"
        return origin_of(address, request.headers, self.config.trusted_proxies, self.config.tls)

    def _peer(self, request: web.Request) -> str:
        peer = request.transport.get_extra_info("peername") if request.transport else None
        return str(peer[0]) if peer else "unknown"

    def same_site(self, request: web.Request) -> bool:
        """Whether the request's ``Origin`` (sent by browsers with every WebSocket and form
        POST) is this server as the browser reached it; a request without one is no
        browser's cross-site request."""
        said = request.headers.get("Origin")
        if said is None:
            return True
        parts = urlsplit(said)
        return parts.netloc.lower() == request.host.lower() and parts.scheme in ("http", "https")

    def current_login(self, request: web.Request) -> tuple[str | None, Login | None]:
        login_id = request.cookies.get(SESSION_COOKIE)
        login = self.logins.get(login_id)
        if login is None:
            return login_id, None
        user = self.desk.known(login.user)
        if user is None:  # taken out of the users file since: logged out
            self.logins.close(login_id)
            log.info("logout: %s is no longer in the users file", shown(login.user))
            return login_id, None
        login.role = user.role
        return login_id, login

    def _set_login_cookie(self, response: web.StreamResponse, login_id: str, secure: bool) -> None:
        response.set_cookie(
            SESSION_COOKIE,
            login_id,
            max_age=int(self.config.login_lifetime),
            path="/",
            secure=secure,
            httponly=True,
            samesite="Strict",
        )

    def _header_login(self, request: web.Request) -> Login | str | None:
        """A login by the trusted header: the login, the refusal's reason, or None."""
        config = self.config
        said = header_login(
            config.user_header, self._peer(request), request.headers, config.trusted_proxies
        )
        if said.refused:
            return said.refused
        if not said.user:
            return None
        user = self.desk.known(said.user)
        if user is None:
            return f"{config.user_header} names {shown(said.user)}, who is not in the users file"
        login_id, login = self.logins.open(user.name, user.role, config.user_header)
        request[NEW_LOGIN] = login_id
        log.info("login: %s (%s) from %s by the %s header", user.name, user.role,
                 self.origin(request).address, config.user_header)  # fmt: skip
        return login

    # -- pages -------------------------------------------------------------------------------
    async def index(self, request: web.Request) -> web.StreamResponse:
        _, login = self.current_login(request)
        if login is None and self.config.user_header:
            found = self._header_login(request)
            if isinstance(found, str):
                self.say_now_and_then(f"header {self._peer(request)}", "login refused: %s",
                                      found)  # fmt: skip
                return web.Response(status=403, text="You are not signed on for this workbench.\n")
            login = found
        if login is None:
            raise web.HTTPSeeOther("/login")
        response = web.Response(
            text=terminal_page(login.user, login.role, login.csrf), content_type="text/html"
        )
        if NEW_LOGIN in request:
            self._set_login_cookie(response, request[NEW_LOGIN], self.origin(request).secure)
        return response

    async def no_icon(self, request: web.Request) -> web.Response:
        return web.Response(status=204)

    async def login_form(self, request: web.Request, message: str = "", status: int = 200
                         ) -> web.Response:  # fmt: skip
        token = request.cookies.get(CSRF_COOKIE) or ""
        if not token or len(token) > 128:
            token = new_token()
        response = web.Response(
            status=status,
            text=login_page(token, message, header_mode=bool(self.config.user_header)),
            content_type="text/html",
        )
        response.set_cookie(
            CSRF_COOKIE, token, path="/login", httponly=True, samesite="Strict",
            secure=self.origin(request).secure,
        )  # fmt: skip
        return response

    async def login(self, request: web.Request) -> web.StreamResponse:
        where = self.origin(request)
        if self.config.user_header:
            self.say_now_and_then(f"password {where.address}",
                                  "login refused: a password from %s: logins are by the %s "
                                  "header", where.address, self.config.user_header)  # fmt: skip
            return await self.login_form(request, "Log in through the course's sign-on.", 403)
        form = await request.post()
        token = form.get("csrf")
        if not self.same_site(request) or not same_token(
            token if isinstance(token, str) else None, request.cookies.get(CSRF_COOKIE, "")
        ):
            self.say_now_and_then(
                f"form {where.address}",
                "login refused: from %s: the form's token or origin is not this server's",
                where.address,
            )
            return await self.login_form(
                request, "The login form was old or not this server's: try again.", 403
            )
        name, password = form.get("user"), form.get("password")
        if not isinstance(name, str) or not isinstance(password, str) or not name:
            return await self.login_form(request, "Give your login name and password.", 400)
        name, password = name[:64], password[:1024]
        if self.short_of_memory("login", name):
            return await self.login_form(request, SHORT_OF_MEMORY, 503)
        verdict = await self.desk.check(name, password, where.address)
        if verdict.user is None:
            message = "login refused: %s from %s: %s"
            if verdict.checked:
                log.warning(message, shown(name), where.address, verdict.why)
            else:
                self.say_now_and_then(f"unchecked {name} {where.address}", message,
                                      shown(name), where.address, verdict.why)  # fmt: skip
            if verdict.locked:
                log.warning("passwords of %s %s", shown(name), self.desk.lock_words())
            said = (
                "Too many tries: wait a few minutes and try again."
                if not verdict.checked
                else "Wrong login name or password."
            )
            return await self.login_form(request, said, 403)
        user = verdict.user
        login_id, _ = self.logins.open(user.name, user.role, "password")
        log.info("login: %s (%s) from %s with a password", user.name, user.role, where.address)
        response = web.HTTPSeeOther("/")
        self._set_login_cookie(response, login_id, where.secure)
        response.del_cookie(CSRF_COOKIE, path="/login")
        raise response

    async def logout(self, request: web.Request) -> web.StreamResponse:
        login_id, login = self.current_login(request)
        form = await request.post()
        token = form.get("csrf")
        if (
            login is None
            or not self.same_site(request)
            or not same_token(token if isinstance(token, str) else None, login.csrf)
        ):
            self.say_now_and_then(f"logout {self.origin(request).address}",
                                  "logout refused from %s: no login or not its form",
                                  self.origin(request).address)  # fmt: skip
            raise web.HTTPForbidden(text="Not logged in here.\n")
        self.logins.close(login_id)
        running = self.apps.get(login.user)
        if running is not None:
            await self.end(running, "You logged out. Your lab progress is saved.")
        log.info("logout: %s", login.user)
        response = web.HTTPSeeOther("/login")
        response.del_cookie(SESSION_COOKIE, path="/")
        raise response

    def short_of_memory(self, what: str, who: str) -> bool:
        if not self.memory.short():
            return False
        self.say_now_and_then(
            "short of memory", "%s of %s refused: the server uses %s, past its ceiling of %s",
            what, shown(who), describe_memory(self.memory.last >> 20),
            describe_memory(self.memory.ceiling),
        )  # fmt: skip
        return True

    # -- the page's WebSocket ----------------------------------------------------------------
    def _page_size(self, request: web.Request) -> tuple[int, int]:
        def number(name: str, default: int) -> int:
            text = request.query.get(name, "")
            return int(text) if text.isdigit() and len(text) <= MAX_SIZE_DIGITS else default

        return self.clamped(number("cols", 80), number("rows", 24), "?")

    def clamped(self, width: int, height: int, user: str) -> tuple[int, int]:
        limits = self.config.limits
        size = limits.terminal_size(max(width, 1), max(height, 1))
        if size != (width, height):
            self.say_now_and_then(
                f"terminal of {user}", "terminal of %s is %dx%d: the app is given %dx%d",
                shown(user), width, height, *size,
            )  # fmt: skip
        return size

    async def websocket(self, request: web.Request) -> web.StreamResponse:
        where = self.origin(request)
        _, login = self.current_login(request)
        if not self.same_site(request):
            self.say_now_and_then(
                f"origin {where.address}", "WebSocket refused: from %s: Origin %s is not "
                "this server's", where.address, shown(request.headers.get("Origin", "")),
            )  # fmt: skip
            raise web.HTTPForbidden(text="This page is not the lab server's.\n")
        if login is None:
            self.say_now_and_then(f"ws {where.address}", "WebSocket refused: from %s: not "
                                  "logged in", where.address)  # fmt: skip
            raise web.HTTPForbidden(text="Log in first.\n")
        if self.short_of_memory("session", login.user):
            raise web.HTTPServiceUnavailable(text=SHORT_OF_MEMORY + "\n")
        size = self._page_size(request)
        student = await self.app_of(login, size)
        if isinstance(student, str):
            socket = web.WebSocketResponse()
            await socket.prepare(request)
            await socket.send_str(Notice("ended", student).text())
            await socket.close()
            return socket
        socket = web.WebSocketResponse(
            max_msg_size=self.config.max_message, heartbeat=30.0, compress=False
        )
        await socket.prepare(request)
        page = student.attach(socket, where.address, size)
        self.pages_open[login.user] += 1
        try:
            await self._read_page(socket, student, login.user, where.address)
        finally:
            self.pages_open[login.user] -= 1
            if self.pages_open[login.user] <= 0:
                del self.pages_open[login.user]
            student.detach(page)
            await page.close()
        return socket

    async def _read_page(
        self, socket: web.WebSocketResponse, student: StudentApp, user: str, address: str
    ) -> None:
        async for message in socket:
            if message.type == WSMsgType.BINARY:
                if student.page is not None and student.page.socket is socket:
                    student.keys(message.data)
            elif message.type == WSMsgType.TEXT:
                self._page_said(student, socket, user, message.data)
            elif message.type == WSMsgType.ERROR:
                self.say_now_and_then(
                    f"ws error {user}", "page of %s from %s closed: %s",
                    user, address, socket.exception(),
                )  # fmt: skip
                return
        if socket.close_code not in (None, 1000, 1001):
            self.say_now_and_then(
                f"ws close {user}", "page of %s from %s closed with code %s",
                user, address, socket.close_code,
            )  # fmt: skip

    def _page_said(
        self, student: StudentApp, socket: web.WebSocketResponse, user: str, text: str
    ) -> None:
        if student.page is None or student.page.socket is not socket:
            return  # a page taken over says nothing more
        try:
            said = json.loads(text)
            if said.get("type") != "resize":
                raise ValueError(said.get("type"))
            cols, rows = int(said["cols"]), int(said["rows"])
        except (ValueError, TypeError, KeyError, AttributeError):
            self.say_now_and_then(f"page said {user}", "a page of %s sent %r: not a message "
                                  "of the page", user, text[:60])  # fmt: skip
            return
        if cols > 0 and rows > 0 and not student.resize(self.clamped(cols, rows, user)):
            self.say_now_and_then(
                f"resizes {user}", "resizes from a page of %s come faster than one per %g s: "
                "the app is given the latest", user, self.config.limits.resize_every,
            )  # fmt: skip

    # -- the student's app -------------------------------------------------------------------
    async def app_of(self, login: Login, size: tuple[int, int]) -> StudentApp | str:
        """The login's user's running app, started if there is none; a message instead when
        none may start."""
        running = self.apps.get(login.user)
        if running is not None and not running.ending and running.app.returncode is None:
            return running
        starting = self._starting.get(login.user)
        if starting is None:
            starting = self._starting[login.user] = asyncio.create_task(
                self._start_app(login, size)
            )
            starting.add_done_callback(lambda _: self._starting.pop(login.user, None))
        return await asyncio.shield(starting)

    async def _start_app(self, login: Login, size: tuple[int, int]) -> StudentApp | str:
        config = self.config
        user = login.user
        limits = config.limits
        why = limits.refusal(0, len(self.apps))
        lease = None
        if why is None:
            try:
                lease, held = self.leases.take(user, limits.per_user, "a browser's page")
            except OSError as exc:
                log.error("session refused: %s: its lease could not be made: %s", user, exc)
                return "The workbench could not be started; tell the instructor."
            if lease is None:
                why = limits.refusal(held, 0)
        if why is not None:
            log.warning("session refused: %s: %s", user, why)
            return why
        assert lease is not None
        try:
            started = await self._start_leased(login, size, lease)
        except BaseException:
            lease.release()
            raise
        if isinstance(started, str):
            lease.release()
        return started

    async def _start_leased(
        self, login: Login, size: tuple[int, int], lease: Lease
    ) -> StudentApp | str:
        config, user = self.config, login.user
        try:
            ports = self.pool.allocate(user, 2)
        except PoolExhausted as exc:
            log.error("session refused: %s: %s", user, exc)
            return "The lab server has no free VIPLE ports left; try again in a few minutes."
        tcp_port, ws_port = ports
        stamp = time.strftime("%Y%m%d-%H%M%S")
        workspace = workspace_folder(config.data_dir, user)
        if config.db:
            await bring_workspace(config.data_dir, config.db, user, workspace, f"web {user}")
        record_dir = workspace / "runs" / stamp
        if record_dir.exists():
            record_dir = workspace / "runs" / f"{stamp}-web"
        spec = AppSpec(
            user, login.role, tcp_port, ws_port, WEB_HINT, config.data_dir, record_dir,
            workspace, *size, "xterm-256color", config.record_quota, uploads=config.uploads,
        )  # fmt: skip
        log_path = config.data_dir / "logs" / user / f"{stamp}-web.log"
        holder: list[StudentApp] = []
        process = AppProcess(
            spec.argv(config.app_command or config.app.command),
            spec.env(),
            log_path,
            lambda data: holder[0].output(data) if holder else None,
            forkserver=self.forkserver,
            settings=spec.settings().to_json(),
            memory=config.limits.app_memory * 1024 * 1024,
            log_size=config.limits.app_log,
        )
        student = StudentApp(
            user, process, grace=config.reattach_grace,
            resize_every=config.limits.resize_every, on_end=self.end, size=size,
        )  # fmt: skip
        holder.append(student)
        student.ports = ports
        student.lease = lease
        try:
            await process.start()
        except OSError as exc:
            self.pool.release(ports)
            log.error("app for %s did not start: %s", user, exc)
            return "The workbench could not be started; tell the instructor."
        self.apps[user] = student
        log.info(
            "session: %s (%s), pid %s (%s), VIPLE tcp %d ws %d",
            user, login.role, process.pid, "forked" if process.forked else "new process",
            tcp_port, ws_port,
        )  # fmt: skip
        background(self._watch(student), name=f"web-app-{user}")
        return student

    async def _watch(self, student: StudentApp) -> None:
        code = await student.app.wait()
        if not student.ending:
            message = (
                "The workbench ended."
                if code == 0
                else (f"The workbench ended with an error ({code}).")
            )
            if code and student.app.ran_out_of_memory():
                message = self.config.limits.memory_message()
            await self.end(student, message)

    async def end(self, student: StudentApp, message: str = "") -> None:
        """Stop a student's app, release its ports, tell its page."""
        if student.ending:
            return
        student.ending = True
        student.cancel_timers()
        page = student.page
        code = await student.app.stop(self.config.stop_grace)
        if self.apps.get(student.user) is student:
            del self.apps[student.user]
        self.pool.release(student.ports)
        if student.lease is not None:
            student.lease.release()
            student.lease = None
        lines = student.app.errors.report()
        if lines:
            log.warning("%s's app log %s", student.user, "\n  ".join(lines))
        log.info("session: %s ended (exit %s) after %.0f s", student.user, code,
                 time.monotonic() - student.started_at)  # fmt: skip
        if page is not None:
            await page.close(Notice("ended", message or "The workbench ended."))

    async def _sweep_idle(self) -> None:
        timeout = self.config.limits.idle_timeout
        period = max(0.2, min(timeout / 4, 30.0))
        while True:
            await asyncio.sleep(period)
            now = time.monotonic()
            for student in list(self.apps.values()):
                if now - student.last_input >= timeout and not student.ending:
                    log.info("%s idle for %s: ending the app", student.user,
                             describe_duration(timeout))  # fmt: skip
                    background(self.end(student, (
                        f"No input for {describe_duration(timeout)}: the session was closed. "
                        "Your lab progress is saved; log in again to go on."
                    )))  # fmt: skip

    # -- files -------------------------------------------------------------------------------
    def _files_login(self, request: web.Request) -> Login:
        _, login = self.current_login(request)
        if login is None:
            self.say_now_and_then(f"files {self.origin(request).address}",
                                  "files refused: from %s: not logged in",
                                  self.origin(request).address)  # fmt: skip
            raise web.HTTPForbidden(text="Log in first.\n")
        return login

    def _files(self, user: str) -> transfer.WorkspaceFiles:
        course = self.course_files
        return transfer.files_of(
            workspace_folder(self.config.data_dir, user),
            self.config.uploads,
            (lambda path: course.changed(user, path)) if course is not None else None,
        )

    async def list_files(self, request: web.Request) -> web.StreamResponse:
        login = self._files_login(request)
        try:
            found = await in_pool(
                FILES, transfer.listing, self._files(login.user), request.query.get("folder", "")
            )
        except transfer.TransferError as exc:
            return web.json_response({"error": str(exc)}, status=400)
        return web.json_response({
            "folder": found.folder,
            "entries": [{"name": e.name, "folder": e.is_folder, "size": e.size}
                        for e in found.entries],
        })  # fmt: skip

    async def upload(self, request: web.Request) -> web.StreamResponse:
        login = self._files_login(request)
        where = self.origin(request)
        if not self.same_site(request):
            self.say_now_and_then(f"upload origin {where.address}", "upload refused: %s from "
                                  "%s: another site's page", login.user, where.address)  # fmt: skip
            return web.json_response({"error": "not this server's page"}, status=403)
        try:
            form = await request.post()
        except web.HTTPRequestEntityTooLarge:
            log.warning("upload refused: %s from %s: larger than %d bytes", login.user,
                        where.address, request.client_max_size)  # fmt: skip
            return web.json_response({"error": "the file is too large"}, status=413)
        token = form.get("csrf") or request.headers.get(FORM_HEADER)
        if not same_token(token if isinstance(token, str) else None, login.csrf):
            self.say_now_and_then(f"upload token {login.user}", "upload refused: %s from %s: "
                                  "not its form's token", login.user, where.address)  # fmt: skip
            return web.json_response({"error": "the form was not this page's: reload"}, status=403)
        sent = form.get("file")
        if not isinstance(sent, web.FileField):
            return web.json_response({"error": "choose a file to send"}, status=400)
        data = await in_pool(FILES, sent.file.read)
        folder = form.get("folder")
        name = f"{folder}/{sent.filename}" if isinstance(folder, str) and folder else sent.filename
        try:
            path = await in_pool(FILES, transfer.upload, self._files(login.user), name, data)
        except transfer.TransferError as exc:
            log.warning("upload refused: %s from %s: %s", login.user, where.address, exc)
            return web.json_response({"error": str(exc)}, status=400)
        log.info("upload: %s sent %s (%d bytes)", login.user, path, len(data))
        return web.json_response({"path": path, "size": len(data)})

    async def download(self, request: web.Request) -> web.StreamResponse:
        login = self._files_login(request)
        path = request.match_info["path"]
        limit = max(self.config.uploads.file_size, self.config.record_quota.record or 0) or (
            64 << 20
        )
        try:
            name, data = await in_pool(FILES, transfer.read, self._files(login.user), path, limit)
        except transfer.TransferError as exc:
            log.warning("download refused: %s from %s: %s", login.user,
                        self.origin(request).address, exc)  # fmt: skip
            return web.Response(status=404, text=f"{exc}\n")
        return web.Response(
            body=data,
            content_type="application/octet-stream",
            headers={"Content-Disposition": f'attachment; filename="{name}"'},
        )
