"""The SSH lab server: logins from the users file, one app process per terminal session,
forwarding only to the user's own VIPLE ports, limits and a clean stop.
"""

from __future__ import annotations

import asyncio
import contextlib
import itertools
import logging
import socket
import time
from collections import Counter
from dataclasses import dataclass, field
from pathlib import Path

import asyncssh

from workbench.control.recording import RecordQuota, shown_size
from workbench.door.applog import make_room
from workbench.door.appproc import (
    RESTORE_TERMINAL,
    AppEntry,
    AppProcess,
    AppSpec,
    app_env,
    forward_hint,
    keep_spares,
)
from workbench.door.checking import PasswordDesk
from workbench.door.course_files import CourseWorkspaces, bring_workspace
from workbench.door.forkserver import ForkServer, ForkServerError
from workbench.door.leases import Lease, SessionLeases
from workbench.door.limits import SessionLimits, describe_duration, describe_memory
from workbench.door.logins import ConnectionGate, Eviction, LoginGuard, LoginPolicy, QuietLog, Stage
from workbench.door.memory import SHORT_OF_MEMORY, MemoryWatch
from workbench.door.networks import Network
from workbench.door.ports import PoolExhausted, PortPool
from workbench.door.serverlog import shown
from workbench.door.sources import source_of
from workbench.door.users import User, UsersFile, users_path
from workbench.files.workspace import workspace_folder
from workbench.files.workspace_files import UploadLimits
from workbench.labs.store.workspace_sync import sync_at_start

from .forwarding import forward, local_forward_refusal, remote_forward_refusal
from .hostkey import host_key_path, load_or_create_host_key
from .openfiles import (
    Handler,
    near_the_limit,
    quiet_accept_errors,
    raise_file_limit,
    room_for_a_file,
)
from .proxy_protocol import ProxyAcceptor, accept_behind_balancer
from .refusals import ASKED_NOTHING, refusal_message
from .sftp import SFTPChannel, SFTPService

log = logging.getLogger("workbench.ssh")

#: what a client closed before it logs in reads (as the reason of the SSH disconnect)
TOO_MANY_WAITING = (
    "The lab server has too many connections waiting to log in from your network or in all; "
    "try again in a minute."
)
OUT_OF_FILES = "The lab server is full; try again in a few minutes."
#: what a client that sat on its place at the login reads when it is closed to make room
MADE_ROOM = (
    "The lab server closed this connection to make room for others: it had not logged in "
    "after {grace:g} s while the places at the login were full; try again."
)
#: seconds a connection from a balancer has to send its PROXY header
PROXY_HEADER_WAIT = 5.0
#: the ciphers the server takes, AES only: a client picks the first of its own list the server
#: has, and OpenSSH's list starts with chacha20-poly1305, which asyncssh does per packet in
#: several Python calls (about five times the CPU of AES-GCM, measured in bench/startup.py);
#: AES-GCM, and AES-CTR with an SHA-2 MAC, are as strong and every SSH client offers them
CIPHERS = (
    "aes128-gcm@openssh.com",
    "aes256-gcm@openssh.com",
    "aes128-ctr",
    "aes192-ctr",
    "aes256-ctr",
)
#: MACs for the CTR ciphers (GCM carries its own): SHA-2 only, encrypt-then-MAC first
MACS = (
    "hmac-sha2-256-etm@openssh.com",
    "hmac-sha2-512-etm@openssh.com",
    "hmac-sha2-256",
    "hmac-sha2-512",
)


@dataclass
class ServerConfig:
    data_dir: Path
    port: int = 2222
    bind: str = ""
    host_key: Path | None = None
    users_file: Path | None = None
    port_range: tuple[int, int] = (41000, 41999)
    public_host: str = ""
    limits: SessionLimits = field(default_factory=SessionLimits)
    #: the app's command before its settings, instead of the entry's (no fork server then)
    app_command: tuple[str, ...] | None = None
    #: fork each app from a fork server that has the app imported (not with ``app_command``)
    fork_server: bool = True
    #: students' apps the fork server keeps started ahead of their sessions (0: none)
    spare_apps: int = 0
    #: seconds between the stop steps of an app (quit, SIGTERM, SIGKILL)
    stop_grace: float = 2.0
    logins: LoginPolicy = field(default_factory=LoginPolicy)
    keepalive_interval: float = 30.0
    #: the app each session runs
    app: AppEntry = field(kw_only=True)
    #: how much room each session's run records may take
    record_quota: RecordQuota = field(default_factory=RecordQuota, kw_only=True)
    #: what a student may upload by SFTP
    uploads: UploadLimits = field(default_factory=UploadLimits, kw_only=True)
    #: the course's PostgreSQL database (None: the SQLite file in the data folder); with one,
    #: each session starts with the student's workspace brought in step with it
    db: str | None = field(default=None, repr=False, kw_only=True)
    #: the load balancers whose connections start with a PROXY protocol header naming the
    #: student's address (none: every connection is the student's own)
    proxy_from: tuple[Network, ...] = field(default=(), kw_only=True)

    def __post_init__(self) -> None:
        self.data_dir = Path(self.data_dir)
        self.host_key = Path(self.host_key or host_key_path(self.data_dir))
        self.users_file = Path(self.users_file or users_path(self.data_dir))
        self.public_host = self.public_host or socket.getfqdn()


class LabServer:
    """The running server: its users, port pool, live sessions and the asyncssh acceptor."""

    def __init__(self, config: ServerConfig) -> None:
        self.config = config
        # a users file that cannot be read stops the server here, before it listens
        assert config.users_file is not None and config.host_key is not None  # __post_init__
        self.users = UsersFile(config.users_file)
        self.host_key = load_or_create_host_key(config.host_key)
        self.pool = PortPool(*config.port_range)
        self.sessions: dict[int, LabSession] = {}
        #: every door's sessions in this data folder, for the per-user cap
        self.leases = SessionLeases(config.data_dir, "ssh")
        self.connections: set[LabConnection] = set()
        #: connections logged in, per user
        self.user_connections: Counter[str] = Counter()
        self.file_limit = 0
        self.remote_listens: dict[str, Counter[int]] = {}
        self.guard = LoginGuard(config.logins)
        self.gate: ConnectionGate[LabConnection] = ConnectionGate(config.logins)
        self.desk = PasswordDesk(self.users, self.guard, self.gate)
        self.quiet_log = QuietLog()
        self.memory = MemoryWatch(config.limits.server_memory)
        self._ids = itertools.count(1)
        self._acceptor: asyncssh.SSHAcceptor | ProxyAcceptor | None = None
        self._sweeper: asyncio.Task[None] | None = None
        self._closing = False
        self._previous_handler: Handler = None
        self.forkserver: ForkServer | None = None
        self.sftp = SFTPService(
            config.data_dir,
            config.uploads,
            room=lambda: room_for_a_file(self.file_limit),
            say=lambda key, line: self.say_now_and_then(key, "%s", line),
        )
        #: with a course database, uploads go on to it (and so to every server of the course)
        self.course_files = CourseWorkspaces(config.data_dir, config.db) if config.db else None
        if self.course_files is not None:
            self.sftp.on_change = self.course_files.changed

    @property
    def port(self) -> int:
        assert self._acceptor is not None
        return self._acceptor.get_port()

    async def start(self) -> None:
        config = self.config
        files_before, self.file_limit = raise_file_limit()
        self._previous_handler = quiet_accept_errors(
            asyncio.get_running_loop(), lambda key, line: self.say_now_and_then(key, "%s", line)
        )
        await self._start_forkserver()
        try:
            self._acceptor = await self._listen()
        except BaseException:
            if self.forkserver is not None:
                await self.forkserver.close()
            raise
        self._sweeper = asyncio.create_task(self._sweep_idle(), name="ssh-idle-sweeper")
        log.info(
            "serving on %s port %d for %d users (%s); VIPLE ports %d-%d; host key %s",
            config.bind or "all addresses", self.port, len(self.users.users),
            config.users_file, *config.port_range, self.host_key.get_fingerprint(),
        )  # fmt: skip
        logins = config.logins
        log.info(
            "logins: %g s to log in; at most %d connections not logged in (%d per address), "
            "those past %g s making room for new ones when full; passwords locked for %s "
            "after %d failures",
            logins.login_timeout, logins.max_unauthenticated,
            logins.max_unauthenticated_per_address, logins.unauthenticated_grace,
            describe_duration(logins.lock_for), logins.lock_after,
        )  # fmt: skip
        limits = config.limits
        raised = f" (raised from {files_before})" if files_before != self.file_limit else ""
        log.info(
            "limits: %d connections per user, %d channels per connection (%g s to ask for "
            "something); terminals at most %dx%d; app memory %s; "
            "app logs %s each, %s per user; %d open files%s; server memory %s",
            limits.connections_per_user, limits.channels_per_connection,
            limits.channel_grace, limits.max_columns, limits.max_rows,
            describe_memory(limits.app_memory) if limits.app_memory else "not capped",
            shown_size(limits.app_log) if limits.app_log else "not capped",
            shown_size(limits.user_logs) if limits.user_logs else "not capped",
            self.file_limit, raised,
            describe_memory(limits.server_memory) if limits.server_memory else "not watched",
        )  # fmt: skip

    async def _listen(self) -> asyncssh.SSHAcceptor | ProxyAcceptor:
        config = self.config
        options = dict(
            server_factory=lambda: LabConnection(self),
            server_host_keys=[self.host_key],
            encryption_algs=CIPHERS,
            mac_algs=MACS,
            encoding=None,
            line_editor=False,
            allow_scp=False,
            agent_forwarding=False,
            x11_forwarding=False,
            login_timeout=config.logins.login_timeout,
            keepalive_interval=config.keepalive_interval,
            keepalive_count_max=4,
            server_version="workbench",
        )
        if not config.proxy_from:
            return await asyncssh.listen(config.bind or None, config.port, **options)
        log.info(
            "connections from %s start with a PROXY header naming the client",
            ", ".join(map(str, config.proxy_from)),
        )
        return await accept_behind_balancer(
            config.bind,
            config.port,
            config.proxy_from,
            lambda key, line: self.say_now_and_then(key, "%s", line),
            min(PROXY_HEADER_WAIT, config.logins.login_timeout),
            **options,
        )

    async def _start_forkserver(self) -> None:
        """Start the fork server, or say why apps start as new processes."""
        config = self.config
        if config.app_command is not None or not config.fork_server:
            why = "--no-fork-server" if not config.fork_server else "an app command is set"
            log.info("apps start as new processes (%s)", why)
            return
        forkserver = ForkServer(app_env(), config.app.main, config.app.preload)
        try:
            await forkserver.start()
        except ForkServerError as exc:
            log.error("the fork server did not start (%s): apps start as new processes", exc)
            return
        self.forkserver = forkserver
        log.info(
            "apps are forked from a fork server (pid %s, %d modules preloaded in %.2f s)",
            forkserver.pid,
            forkserver.modules,
            forkserver.seconds,
        )
        keep_spares(forkserver, config.spare_apps, config.app, config.data_dir,
                    config.record_quota, config.uploads)  # fmt: skip

    async def close(self) -> None:
        """End every session (their apps stopped and reaped), then stop listening."""
        self._closing = True
        if self._sweeper is not None:
            self._sweeper.cancel()
        if self._acceptor is not None:
            self._acceptor.close()
        sessions = list(self.sessions.values())
        if sessions:
            log.info("stopping: ending %d sessions", len(sessions))
        await asyncio.gather(*(s.end("The lab server is stopping.") for s in sessions))
        connections = [c.conn for c in self.connections if c.conn is not None]
        for conn in connections:  # forwarding-only connections too
            conn.close()
        for conn in connections:
            with contextlib.suppress(Exception):
                await asyncio.wait_for(conn.wait_closed(), 5)
        if self._acceptor is not None:
            await self._acceptor.wait_closed()
        if self.forkserver is not None:
            await self.forkserver.close()
        if self.course_files is not None:
            await self.course_files.close_at_stop(log)
        asyncio.get_running_loop().set_exception_handler(self._previous_handler)

    async def __aenter__(self) -> LabServer:
        await self.start()
        return self

    async def __aexit__(self, *exc: object) -> None:
        await self.close()

    def penalty_started(self, source: str) -> None:
        self.say_now_and_then(
            f"penalty {source}",
            "connections from %s refused for %.0f s: they held places at the login without "
            "logging in",
            source,
            self.gate.penalties.refused_for(source),
        )

    def say_now_and_then(self, key: str, message: str, *args: object) -> None:
        """Log a warning that an attacker could repeat thousands of times, once per 10 s."""
        held = self.quiet_log.due(key)
        if held is None:
            return
        if held:
            message += f" ({held} more like it not logged)"
        log.warning(message, *args)

    def short_of_memory(self, what: str, who: str) -> bool:
        """Whether the server is past its memory ceiling: then ``what`` (new work) of ``who``
        is refused, and said in the log now and then."""
        if not self.memory.short():
            return False
        self.say_now_and_then(
            "short of memory",
            "%s of %s refused: the server uses %s, past its ceiling of %s",
            what, who, describe_memory(self.memory.last >> 20),
            describe_memory(self.memory.ceiling),
        )  # fmt: skip
        return True

    # -- sessions ----------------------------------------------------------------------------
    def live(self, user: str) -> list[LabSession]:
        return [s for s in self.sessions.values() if s.user.name == user and s.running]

    def held_remote_ports(self, user: str) -> set[int]:
        return {p for p, n in self.remote_listens.get(user, Counter()).items() if n > 0}

    async def _sweep_idle(self) -> None:
        timeout = self.config.limits.idle_timeout
        period = max(0.2, min(timeout / 4, 30.0))
        while True:
            await asyncio.sleep(period)
            now = time.monotonic()
            idle = [
                s for s in self.sessions.values() if s.running and now - s.last_input >= timeout
            ]
            for session in idle:
                log.info(
                    "session %d of %s idle for %s: ending it",
                    session.id,
                    session.user.name,
                    describe_duration(timeout),
                )
            message = (
                f"No input for {describe_duration(timeout)}: the session was closed. "
                "Your lab progress is saved; log in again to go on."
            )
            if idle:
                await asyncio.gather(*(s.end(message) for s in idle))


class LabConnection(asyncssh.SSHServer):
    """One SSH connection: who logs in, and which forwards and sessions it may open."""

    def __init__(self, server: LabServer) -> None:
        self.server = server
        self.conn: asyncssh.SSHServerConnection | None = None
        self.peer = "?"
        self.username = ""
        self.user: User | None = None
        self.failed = False
        self.remote_ports: Counter[int] = Counter()
        #: closed to make room at the login for a newer connection
        self.evicted = False
        #: counted among its user's logged-in connections
        self.holds_place = False
        #: logged in, and closed at once: its user held too many connections
        self.over_cap = False
        #: session and forward channels open on this connection
        self.channels = 0
        self._pending_key = "?"
        self._login: tuple[User, str] | None = None

    # -- connection --------------------------------------------------------------------------
    def connection_made(self, conn: asyncssh.SSHServerConnection) -> None:
        self.conn = conn
        server = self.server
        server.connections.add(self)
        peer = conn.get_extra_info("peername")
        # behind a balancer, the address its PROXY header named
        self.peer = conn.get_extra_info("client_address") or (str(peer[0]) if peer else "?")
        sock = conn.get_extra_info("socket")
        if sock is not None and near_the_limit(sock.fileno(), server.file_limit):
            self._turn_away(
                "out of files",
                f"{sock.fileno()} of the server's {server.file_limit} open files are in use",
                OUT_OF_FILES,
            )
            return
        if server.short_of_memory("connection", self.peer):
            self._turn_away("short of memory", "the server is short of memory", SHORT_OF_MEMORY)
            return
        admission = server.gate.admit(self, self.peer)
        if admission.refused is not None:
            self._turn_away(f"turned away {self.peer}", admission.refused, TOO_MANY_WAITING)
            return
        if admission.evicted is not None:
            self._make_room(admission.evicted)
        # agent and X11 forwarding are off; these make their refusals show in the log (asyncssh
        # has no hook for that, so its methods are replaced; the X11 one refuses whatever it gets)
        conn.create_agent_listener = self._refuse_agent  # type: ignore[method-assign]
        conn.attach_x11_listener = self._refuse_x11  # type: ignore[method-assign, assignment]

    def _turn_away(self, key: str, why: str, message: str) -> None:
        """Close the connection at once with ``message`` for the client; log ``why`` (the
        same ``key`` at most once per 10 s)."""
        self.server.say_now_and_then(key, "connection from %s closed: %s", self.peer, why)
        assert self.conn is not None
        # after asyncssh has sent its version, so the client reads the reason
        asyncio.get_running_loop().call_soon(
            self.conn.disconnect, asyncssh.DISC_TOO_MANY_CONNECTIONS, message
        )

    def _make_room(self, eviction: Eviction[LabConnection]) -> None:
        """Close the connection that gave up its place at the login for this one."""
        server, victim = self.server, eviction.key
        victim.evicted = True
        server.say_now_and_then(
            "made room",
            "connection from %s closed to make room for one from %s: it held a place at the "
            "login for %.0f s without logging in (%s holds %d more)",
            victim.peer, self.peer, eviction.held, eviction.source,
            server.gate.unauthenticated[eviction.source],
        )  # fmt: skip
        if eviction.penalized:
            server.penalty_started(eviction.source)
        if victim.conn is not None:
            grace = server.config.logins.unauthenticated_grace
            victim.conn.disconnect(
                asyncssh.DISC_TOO_MANY_CONNECTIONS, MADE_ROOM.format(grace=grace)
            )

    def _settle(self, logged_in: bool) -> None:
        if self.server.gate.settled(self, logged_in):
            self.server.penalty_started(source_of(self.peer))

    def connection_lost(self, exc: Exception | None) -> None:
        self._settle(logged_in=False)
        self.server.connections.discard(self)
        if self.holds_place:
            self.holds_place = False
            assert self.user is not None
            counts = self.server.user_connections
            counts[self.user.name] -= 1
            if counts[self.user.name] <= 0:
                del counts[self.user.name]
        gave_up = not (self.failed or self.over_cap or self.evicted)
        if self.username and self.user is None and gave_up:
            # every offered key was refused and the client gave up
            self.server.guard.key_failed(self.peer)
            self.server.say_now_and_then(
                f"no key {self.peer}",
                "login failed: %s from %s (no accepted key)",
                shown(self.username),
                self.peer,
            )
        if self.user is not None and self.remote_ports:
            held = self.server.remote_listens.get(self.user.name)
            if held is not None:
                held.subtract(self.remote_ports)

    async def _refuse_agent(self) -> bool:
        log.warning("agent forwarding refused: %s from %s", shown(self.username), self.peer)
        return False

    async def _refuse_x11(self, *args: object) -> None:
        log.warning("X11 forwarding refused: %s from %s", shown(self.username), self.peer)
        return None

    def tun_requested(self, unit: int | None) -> bool:
        log.warning("tunnel (tun) refused: %s from %s", shown(self.username), self.peer)
        return False

    def tap_requested(self, unit: int | None) -> bool:
        log.warning("tunnel (tap) refused: %s from %s", shown(self.username), self.peer)
        return False

    # -- authentication ----------------------------------------------------------------------
    def begin_auth(self, username: str) -> bool:
        self.username = username
        self.server.gate.progressed(self, Stage.AUTHENTICATING)
        return True

    def _known(self, username: str) -> User | None:
        return self.server.desk.known(username)

    def _refused(self, username: str, why: str, *, checked: bool = True) -> None:
        """Log a refused password; unchecked ones (which cost nothing) at most once per 10 s."""
        self.failed = True
        message = "login refused: %s from %s: %s"
        if checked:
            log.warning(message, shown(username), self.peer, why)
        else:
            key = f"unchecked {username} {self.peer}"
            self.server.say_now_and_then(key, message, shown(username), self.peer, why)

    def _accepted(self, user: User, how: str) -> None:
        """Let the user in, unless they hold as many connections as one user may (or the
        connection was closed to make room while its password was checked)."""
        server = self.server
        if self.evicted:
            return
        self._settle(logged_in=True)
        why = server.config.limits.connection_refusal(server.user_connections[user.name])
        if why is not None:
            self.over_cap = True
            server.say_now_and_then(
                f"connections of {user.name}",
                "login refused: %s from %s: %d connections logged in already",
                user.name,
                self.peer,
                server.user_connections[user.name],
            )
            assert self.conn is not None
            self.conn.disconnect(asyncssh.DISC_TOO_MANY_CONNECTIONS, why)
            return
        self.user = user
        self.holds_place = True
        server.user_connections[user.name] += 1
        log.info("login: %s (%s) from %s with %s", user.name, user.role, self.peer, how)

    def public_key_auth_supported(self) -> bool:
        return True

    def validate_public_key(self, username: str, key: asyncssh.SSHKey) -> bool:
        user = self._known(username)
        if user is not None and user.keys and user.accepts_key(key):
            self._pending_key = key.get_fingerprint()
            return True
        return False

    def auth_completed(self) -> None:
        if self._login is not None:  # by password
            self._accepted(*self._login)
            return
        # by key: validate_public_key cannot tell a query from a login
        user = self._known(self.username)
        if user is not None:
            self._accepted(user, f"key {self._pending_key}")

    def password_auth_supported(self) -> bool:
        return True

    async def validate_password(self, username: str, password: str) -> bool:
        server = self.server
        server.gate.progressed(self, Stage.CHECKING)
        try:
            verdict = await server.desk.check(username, password, self.peer)
        finally:
            server.gate.progressed(self, Stage.AUTHENTICATING)
        if verdict.user is not None:
            self._login = (verdict.user, "password")
            return True
        self._refused(username, verdict.why, checked=verdict.checked)
        if verdict.locked:
            log.warning(
                "passwords of %s %s (keys still work)", shown(username), server.desk.lock_words()
            )
        return False

    # -- channels ----------------------------------------------------------------------------
    def _take_channel(self, kind: str) -> None:
        """Count one more channel of ``kind`` on this connection, or refuse it (past the cap,
        or while the server is short of memory) with the reason and one log line now and
        then."""
        assert self.user is not None
        server = self.server
        if server.short_of_memory(f"{kind} channel", self.user.name):
            raise asyncssh.ChannelOpenError(asyncssh.OPEN_RESOURCE_SHORTAGE, SHORT_OF_MEMORY)
        why = server.config.limits.channel_refusal(self.channels)
        if why is not None:
            server.say_now_and_then(
                f"channels of {self.user.name}",
                "%s channel refused: %s from %s: %s",
                kind, self.user.name, self.peer, why,
            )  # fmt: skip
            raise asyncssh.ChannelOpenError(asyncssh.OPEN_RESOURCE_SHORTAGE, f"lab server: {why}")
        self.channels += 1

    def release_channel(self) -> None:
        self.channels = max(0, self.channels - 1)

    def session_requested(self) -> LabSession | bool:
        if self.user is None or self.server._closing:
            return False
        self._take_channel("session")
        return LabSession(self.server, self, self.user)

    def connection_requested(
        self, dest_host: str, dest_port: int, orig_host: str, orig_port: int
    ) -> bool:
        user = self.user
        if user is None:
            return False
        ports = {s.spec.tcp_port for s in self.server.live(user.name) if s.spec}
        why = local_forward_refusal(dest_host, dest_port, ports)
        if why is not None:
            log.warning(
                "forward refused: %s from %s to %s:%d: %s",
                user.name,
                self.peer,
                dest_host,
                dest_port,
                why,
            )
            raise asyncssh.ChannelOpenError(
                asyncssh.OPEN_ADMINISTRATIVELY_PROHIBITED, f"forward refused: {why}"
            )
        self._take_channel("forward")
        log.info("forward: %s to %s:%d", user.name, dest_host, dest_port)
        return forward(dest_host, dest_port, self.release_channel)  # type: ignore[return-value]

    def server_requested(self, listen_host: str, listen_port: int) -> bool:
        user = self.user
        if user is None:
            return False
        ports = {s.spec.ws_port for s in self.server.live(user.name) if s.spec}
        why = remote_forward_refusal(listen_host, listen_port, ports)
        if why is not None:
            log.warning(
                "remote forward refused: %s from %s on %s:%d: %s",
                user.name,
                self.peer,
                listen_host,
                listen_port,
                why,
            )
            return False
        log.info("remote forward: %s listens on %s:%d", user.name, listen_host, listen_port)
        self.remote_ports[listen_port] += 1
        self.server.remote_listens.setdefault(user.name, Counter())[listen_port] += 1
        return True

    def unix_connection_requested(self, dest_path: str) -> bool:
        log.warning("forward refused: %s to socket %s", self.username, shown(dest_path))
        return False

    def unix_server_requested(self, listen_path: str) -> bool:
        log.warning("remote forward refused: %s on socket %s", self.username, shown(listen_path))
        return False


class LabSession(asyncssh.SSHServerSession):
    """One SSH session channel: a terminal running the workbench app, or a clear refusal."""

    def __init__(self, server: LabServer, connection: LabConnection, user: User) -> None:
        self.server = server
        self.connection = connection
        self.user = user
        self.id = next(server._ids)
        self.chan: asyncssh.SSHServerChannel | None = None
        self.term = ""
        self.size = (80, 24)
        self.has_pty = False
        self.request = ""  # shell, or what was refused
        self.command = ""
        self.spec: AppSpec | None = None
        self.app: AppProcess | None = None
        self.ports: tuple[int, ...] = ()
        #: the session's place among the user's sessions of every door (see door/leases.py)
        self.lease: Lease | None = None
        self.last_input = time.monotonic()
        self.started_at = time.monotonic()
        self._ending: asyncio.Task[None] | None = None
        self._runner: asyncio.Task[None] | None = None
        self._closed = False
        self._log_reported = False
        #: the size the app was last given, when, and the pass-on of a newer one, if waiting
        self._app_size = self.size
        self._resized_at = 0.0
        self._resize: asyncio.TimerHandle | None = None
        #: a file transfer (the ``sftp`` subsystem) runs on this channel instead of the app
        self.sftp: SFTPChannel | None = None
        #: closes the channel if it asks for nothing within the grace
        self._grace: asyncio.TimerHandle | None = None
        #: the channel's place among its connection's channels, not given back yet
        self._counted = True

    @property
    def running(self) -> bool:
        return self.app is not None and self.app.returncode is None and self._ending is None

    # -- requests ----------------------------------------------------------------------------
    def connection_made(self, chan: asyncssh.SSHServerChannel) -> None:
        self.chan = chan
        grace = self.server.config.limits.channel_grace
        if grace > 0:
            self._grace = asyncio.get_running_loop().call_later(grace, self._asked_nothing)

    def _asked(self) -> None:
        """The channel asked for something: the grace is over."""
        if self._grace is not None:
            self._grace.cancel()
            self._grace = None

    def _asked_nothing(self) -> None:
        """Close a channel that asked for no terminal, command or subsystem in time."""
        self._grace = None
        if self.request or self.chan is None or self._closed:
            return
        grace = self.server.config.limits.channel_grace
        self.server.say_now_and_then(
            f"asked nothing {self.user.name}",
            "session channel closed: %s from %s asked for nothing within %g s",
            self.user.name, self.connection.peer, grace,
        )  # fmt: skip
        self._closed = True
        with contextlib.suppress(Exception):
            self.chan.write_stderr(ASKED_NOTHING.format(grace=grace).encode() + b"\r\n")
            self.chan.exit(1)

    def pty_requested(self, term_type: str, term_size, term_modes) -> bool:
        self.has_pty = True
        self.term = term_type or "xterm-256color"
        width, height = term_size[0], term_size[1]
        if width > 0 and height > 0:
            self.size = self._clamped(width, height)
        return True

    def _clamped(self, width: int, height: int) -> tuple[int, int]:
        """The terminal size the app is given (a huge one would take its memory and CPU)."""
        size = self.server.config.limits.terminal_size(width, height)
        if size != (width, height):
            self.server.say_now_and_then(
                f"terminal of {self.user.name}",
                "terminal of %s from %s is %dx%d: the app is given %dx%d",
                self.user.name, self.connection.peer, width, height, *size,
            )  # fmt: skip
        return size

    def shell_requested(self) -> bool:
        self._asked()
        self.request = "shell"
        return True

    def exec_requested(self, command: str) -> bool:
        self._asked()
        self.request = f"command {command[:60]!r}"
        self.command = command[:200]
        return True

    def subsystem_requested(self, subsystem: str) -> bool:
        self._asked()
        self.request = f"subsystem {subsystem[:30]!r}"
        if subsystem == "sftp" and self.chan is not None:
            self.sftp = SFTPChannel(self.server.sftp, self.user, self.connection.peer)
            self.sftp.connection_made(self.chan)
        return True

    def session_started(self) -> None:
        if self.server.short_of_memory(self.request or "session", self.user.name):
            assert self.chan is not None
            self._closed = True
            self.chan.write_stderr(SHORT_OF_MEMORY.encode() + b"\r\n")
            self.chan.exit(1)
            return
        if self.sftp is not None and self.chan is not None:
            self.sftp.start(self.chan, self.server.config.limits.connections_per_user)
            return
        if self.request != "shell" or not self.has_pty:
            self._refuse_request()
            return
        why = self._take_lease()
        if why is not None:
            log.warning(
                "session refused: %s from %s: %s", self.user.name, self.connection.peer, why
            )
            self._say_and_exit(why, 1)
            return
        self.server.sessions[self.id] = self
        self._runner = asyncio.create_task(self._run(), name=f"ssh-session-{self.id}")

    def _take_lease(self) -> str | None:
        """Take this session's place among the user's sessions of every door (the lease),
        or say why it may not open: the server full, or the user at their cap."""
        server, user = self.server, self.user.name
        limits = server.config.limits
        why = limits.refusal(0, len(server.sessions))
        if why is not None:
            return why
        try:
            self.lease, held = server.leases.take(
                user, limits.per_user, f"session {self.id} from {self.connection.peer}"
            )
        except OSError as exc:
            log.error("session refused: %s: its lease could not be made: %s", user, exc)
            return "The workbench could not be started; tell the instructor."
        return None if self.lease is not None else limits.refusal(held, 0)

    def _forget(self) -> bool:
        """Leave the server's sessions and let go of the lease; whether it was one of them."""
        if self.lease is not None:
            self.lease.release()
            self.lease = None
        return self.server.sessions.pop(self.id, None) is not None

    def _refuse_request(self) -> None:
        config = self.server.config
        message = refusal_message(
            self.request, self.command, self.server.port, self.user.name, config.public_host
        )
        log.warning(
            "%s refused: %s from %s",
            self.request or "session without terminal",
            self.user.name,
            self.connection.peer,
        )
        assert self.chan is not None
        self.chan.write_stderr(message.encode() + b"\r\n")
        self.chan.exit(1)

    def _say_and_exit(self, message: str, status: int) -> None:
        chan = self.chan
        if chan is None or self._closed:
            return
        self._closed = True
        with contextlib.suppress(Exception):
            chan.write(b"\r" + message.encode() + b"\r\n")
            chan.exit(status)

    # -- the app -----------------------------------------------------------------------------
    async def _run(self) -> None:
        server, config = self.server, self.server.config
        user = self.user.name
        try:
            self.ports = server.pool.allocate(user, 2, owned=server.held_remote_ports(user))
        except PoolExhausted as exc:
            log.error("session refused: %s: %s", user, exc)
            self._forget()
            self._say_and_exit(
                "The lab server has no free VIPLE ports left; try again in a few minutes.", 1
            )
            return
        tcp_port, ws_port = self.ports
        stamp = time.strftime("%Y%m%d-%H%M%S")
        workspace = workspace_folder(config.data_dir, user)
        if config.db:
            await self._bring_workspace(user, workspace)
        runs = workspace / "runs"
        record_dir = runs / stamp
        if record_dir.exists() or any(
            s.spec and s.spec.record_dir == record_dir for s in server.sessions.values()
        ):
            record_dir = runs / f"{stamp}-{self.id}"
        hint = forward_hint(user, config.public_host, server.port, tcp_port, ws_port)
        width, height = self._app_size = self.size
        self.spec = AppSpec(
            user,
            self.user.role,
            tcp_port,
            ws_port,
            hint,
            config.data_dir,
            record_dir,
            workspace,
            width,
            height,
            self.term,
            config.record_quota,
            uploads=config.uploads,
        )
        log_path = config.data_dir / "logs" / user / f"{stamp}-{self.id}.log"
        self._make_log_room(log_path)
        self.app = AppProcess(
            self.spec.argv(config.app_command or config.app.command),
            self.spec.env(),
            log_path,
            self._output,
            forkserver=server.forkserver,
            settings=self.spec.settings().to_json(),
            memory=config.limits.app_memory * 1024 * 1024,
            log_size=config.limits.app_log,
        )
        try:
            await self.app.start()
        except OSError as exc:
            log.error("app for %s did not start: %s", user, exc)
            await self._finish("The workbench could not be started; tell the instructor.", 1)
            return
        if self._ending is not None:  # the client left while the app was starting
            await self.app.stop(config.stop_grace)
            return
        log.info(
            "session %d: %s (%s) from %s, pid %s (%s), VIPLE tcp %d ws %d, %dx%d",
            self.id,
            user,
            self.user.role,
            self.connection.peer,
            self.app.pid,
            "forked" if self.app.forked else "new process",
            tcp_port,
            ws_port,
            width,
            height,
        )
        code = await self.app.wait()
        if self._ending is None:  # the app ended by itself (ctrl+q, or a crash)
            message = "" if code == 0 else f"The workbench ended with an error ({code})."
            if code and self.app.ran_out_of_memory():
                limits = config.limits
                log.warning(
                    "session %d: %s's app ended at its memory cap (%s)",
                    self.id, user, describe_memory(limits.app_memory),
                )  # fmt: skip
                message = limits.memory_message()
            await self._finish(message, code)

    async def _bring_workspace(self, user: str, workspace: Path) -> None:
        config = self.server.config
        assert config.db is not None
        await bring_workspace(
            config.data_dir, config.db, user, workspace, f"session {self.id}", sync_at_start
        )

    def _make_log_room(self, log_path: Path) -> None:
        """Remove the user's oldest logs until their folder has room for this session's."""
        limits, server = self.server.config.limits, self.server
        writing = {
            path
            for s in server.sessions.values()
            if s.app is not None
            for path in (s.app.errors.path, s.app.errors.rotated)
        }
        removed, freed = make_room(log_path.parent, limits.user_logs, 2 * limits.app_log, writing)
        if removed:
            log.info(
                "session %d: removed %s's %d oldest app logs (%s) to keep their logs within %s",
                self.id, self.user.name, removed, shown_size(freed), shown_size(limits.user_logs),
            )  # fmt: skip

    def _output(self, data: bytes) -> None:
        if self.chan is not None and not self._closed:
            self.chan.write(data)

    async def end(self, message: str = "") -> None:
        """Stop this session's app (quit, SIGTERM, SIGKILL), release its ports, close."""
        if self._ending is None:
            self._ending = asyncio.create_task(self._stop(message))
        await asyncio.shield(self._ending)

    async def _stop(self, message: str) -> None:
        code = None
        if self.app is not None:
            code = await self.app.stop(self.server.config.stop_grace)
        if self._runner is not None:
            with contextlib.suppress(Exception, asyncio.CancelledError):
                await self._runner
        await self._finish(message, 1 if message else (code or 0))

    async def _finish(self, message: str, status: int) -> None:
        server = self.server
        if self.app is not None and not self._log_reported:
            self._log_reported = True
            lines = self.app.errors.report()
            if lines:
                log.warning(
                    "session %d: %s's app log %s",
                    self.id, self.user.name, "\n  ".join(lines),
                )  # fmt: skip
        if self._forget() and self.app is not None:
            log.info(
                "session %d: %s ended (exit %s) after %.0f s",
                self.id,
                self.user.name,
                self.app.returncode,
                time.monotonic() - self.started_at,
            )
        server.pool.release(self.ports)
        self.ports = ()
        if self._resize is not None:
            self._resize.cancel()
            self._resize = None
        if self.chan is not None and not self._closed:
            with contextlib.suppress(Exception):
                self.chan.write(RESTORE_TERMINAL)
            if message:
                self._say_and_exit(message, status)
            else:
                self._exit(status)

    def _exit(self, status: int) -> None:
        self._closed = True
        with contextlib.suppress(Exception):
            assert self.chan is not None
            self.chan.exit(status)

    # -- the client --------------------------------------------------------------------------
    def data_received(self, data: bytes, datatype: asyncssh.DataType) -> None:
        if self.sftp is not None:
            self.sftp.stream.data_received(data, datatype)
            return
        self.last_input = time.monotonic()
        if self.app is not None:
            self.app.send_keys(data)

    def terminal_size_changed(self, width: int, height: int, pixwidth: int, pixheight: int) -> None:
        """Pass the new size on, clamped, at most once per ``resize_every`` seconds: of a
        storm of changes the app gets the latest only."""
        if width <= 0 or height <= 0:
            return
        self.size = self._clamped(width, height)
        if self._resize is not None:
            return  # a pass-on is waiting: it takes the size as it is then
        wait = self._resized_at + self.server.config.limits.resize_every - time.monotonic()
        if wait <= 0:
            self._pass_size_on()
        else:
            self._resize = asyncio.get_running_loop().call_later(wait, self._pass_size_on)

    def _pass_size_on(self) -> None:
        self._resize = None
        if self.app is None or self.size == self._app_size:
            return
        self._resized_at = time.monotonic()
        self._app_size = self.size
        self.app.resize(*self.size)

    def eof_received(self) -> bool:
        if self.sftp is not None:
            return self.sftp.stream.eof_received()
        self._client_gone("end of input")
        return False

    def break_received(self, msec: int) -> bool:
        return False

    def pause_writing(self) -> None:
        if self.sftp is not None:
            self.sftp.stream.pause_writing()
        if self.app is not None:
            self.app.pause_output()

    def resume_writing(self) -> None:
        if self.sftp is not None:
            self.sftp.stream.resume_writing()
        if self.app is not None:
            self.app.resume_output()

    def connection_lost(self, exc: Exception | None) -> None:
        self._asked()
        if self._counted:
            self._counted = False
            self.connection.release_channel()
        if self.sftp is not None:
            self.sftp.stream.connection_lost(exc)
        self._closed = True
        self._client_gone(str(exc) if exc else "disconnected")

    def _client_gone(self, why: str) -> None:
        if self.id in self.server.sessions and self._ending is None:
            log.info("session %d: %s: %s", self.id, self.user.name, why)
            self._ending = asyncio.create_task(self._stop(""))
        elif self._runner is None:
            self._forget()
