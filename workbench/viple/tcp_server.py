"""The Unity-simulator role: a TCP server VIPLE's Robot/IoT Controller (Wi-Fi) connects to.

One JSON object per line each way. A report of every configured sensor is pushed every
``report_ms`` from the moment a program connects, and each accepted command line is answered
at once with a report. One program drives at a time: a second one gets a one-line JSON error
and is closed. Malformed lines, lines that are not UTF-8 and lines over the size limit are
counted, logged and skipped; the connection stays open. A line over the limit is dropped as it
arrives, never buffered whole.

Accepted sockets have TCP keepalive on, so a peer whose machine vanished is noticed. Reports are
written without waiting for the peer (see ``link.Outbox``); a driver that sends nothing and
reads nothing for ``idle_s`` seconds is disconnected and the robot stops.

By default the server listens on 127.0.0.1 and ::1 (VIPLE resolves ``localhost`` to either);
other interfaces only when they are named in ``bind``.
"""

from __future__ import annotations

import asyncio
import contextlib
import errno
import logging
import os
import socket
from collections.abc import Iterator
from dataclasses import dataclass

from workbench.sim.session import Session

from .codec import DEFAULT_MAX_LINE_BYTES, FrameError, LineSplitter
from .link import (
    IDLE_S_DEFAULT,
    REPORT_MS_DEFAULT,
    Cockpit,
    Link,
    LinkStatus,
    Seat,
    check_idle_s,
    check_report_ms,
)
from .sockets import configure_socket

DEFAULT_PORT = 1350
LOOPBACK = ("127.0.0.1", "::1")
READ_SIZE = 65536
#: how long a refused or closing client gets to take its last line
_GOODBYE_SECONDS = 1.0
log = logging.getLogger("workbench.viple.tcp")


class EndpointError(RuntimeError):
    """An endpoint cannot start (port in use, address not available), with the reason."""


@dataclass(frozen=True)
class TcpConfig:
    #: 0 lets the system choose a free port (the same one on every address)
    port: int = DEFAULT_PORT
    #: addresses to listen on; empty means 127.0.0.1 and ::1
    bind: tuple[str, ...] = ()
    report_ms: int = REPORT_MS_DEFAULT
    max_line_bytes: int = DEFAULT_MAX_LINE_BYTES
    #: seconds a driver may send nothing and read nothing before it loses the seat (None: never)
    idle_s: float | None = IDLE_S_DEFAULT

    def __post_init__(self) -> None:
        check_port(self.port)
        check_report_ms(self.report_ms)
        check_idle_s(self.idle_s)
        if not self.max_line_bytes >= 1:
            raise ValueError("max_line_bytes must be at least 1")
        for host in self.bind:
            if not isinstance(host, str) or not host.strip():
                raise ValueError(f"bind address {host!r} is empty")


def check_port(port: object) -> int:
    if isinstance(port, bool) or not isinstance(port, int) or not 0 <= port <= 65535:
        raise ValueError(f"port {port!r} is out of range: use 1 to 65535")
    return port


def format_address(host: str, port: int) -> str:
    return f"[{host}]:{port}" if ":" in host else f"{host}:{port}"


def _peer_of(writer: asyncio.StreamWriter) -> str:
    peer = writer.get_extra_info("peername")
    if isinstance(peer, tuple) and len(peer) >= 2:
        return format_address(str(peer[0]), int(peer[1]))
    return str(peer or "unknown peer")


class _Outbox:
    """A TCP connection's writing side: lines go out with ``\r\n``, never waiting for the peer."""

    def __init__(self, writer: asyncio.StreamWriter) -> None:
        self.writer = writer

    def queued(self) -> int:
        return self.writer.transport.get_write_buffer_size()

    async def write(self, line: str) -> None:
        if self.writer.transport.is_closing():
            raise ConnectionResetError(errno.ECONNRESET, "connection lost")
        self.writer.write(line.encode("utf-8") + b"\r\n")


class TcpServer:
    """Serves ``robot`` (a session, or a station as its :class:`Cockpit`) to one VIPLE program
    at a time over TCP."""

    def __init__(
        self,
        robot: Session | Cockpit,
        config: TcpConfig | None = None,
        seat: Seat | None = None,
        logger: logging.Logger | None = None,
    ) -> None:
        self.config = config or TcpConfig()
        self.log = logger or log
        self.link = Link(robot, "tcp", seat=seat, logger=self.log, idle_s=self.config.idle_s)
        self._servers: list[asyncio.Server] = []
        self._handlers: set[asyncio.Task] = set()
        self.addresses: list[tuple[str, int]] = []

    @property
    def status(self) -> LinkStatus:
        return self.link.status

    @property
    def port(self) -> int:
        """The port listened on (the chosen one when the config asked for 0)."""
        return self.addresses[0][1] if self.addresses else self.config.port

    # -- starting and stopping -------------------------------------------------------------
    async def start(self) -> None:
        """Listen on every configured address; raises ``EndpointError`` when it cannot."""
        hosts = self.config.bind or LOOPBACK
        port = self.config.port
        try:
            for host in hosts:
                server = await self._listen(host, port)
                if server is None:
                    continue
                self._servers.append(server)
                for sock in server.sockets:
                    name = sock.getsockname()
                    self.addresses.append((str(name[0]), int(name[1])))
                port = self.addresses[0][1]
            if not self.addresses:
                raise EndpointError(f"no address to listen on among {', '.join(hosts)}")
        except BaseException:
            await self.close()
            raise
        shown = ", ".join(format_address(h, p) for h, p in self.addresses)
        self.link.address = shown
        self.log.info("listening for VIPLE (Unity simulator role) on %s", shown)

    async def _listen(self, host: str, port: int) -> asyncio.Server | None:
        default_v6 = not self.config.bind and host == "::1"
        try:
            server = await asyncio.start_server(
                self._on_client, host, port, limit=READ_SIZE, reuse_address=True
            )
        except OSError as err:
            if err.errno == errno.EADDRINUSE:
                raise EndpointError(
                    f"port {port} is in use on {host}: stop the other simulator or choose "
                    "--tcp-port"
                ) from None
            if default_v6 and _unavailable(err):
                self.log.warning(
                    "IPv6 loopback ::1 is not available (%s); using 127.0.0.1 only", err
                )
                return None
            raise EndpointError(f"cannot listen on {host} port {port}: {_reason(err)}") from None
        if server.sockets:
            return server
        # asyncio skips an address family the system cannot open a socket for
        server.close()
        if default_v6:
            self.log.warning("IPv6 loopback ::1 is not available; using 127.0.0.1 only")
            return None
        raise EndpointError(f"cannot listen on {host} port {port}: no usable address")

    async def close(self) -> None:
        """Stop listening, close the connection (the robot stops) and wait for it to end."""
        for server in self._servers:
            server.close()
        handlers = list(self._handlers)
        for task in handlers:
            task.cancel()
        if handlers:
            await asyncio.gather(*handlers, return_exceptions=True)
        for server in self._servers:
            with contextlib.suppress(Exception):
                await server.wait_closed()
        self._servers.clear()

    async def __aenter__(self) -> TcpServer:
        await self.start()
        return self

    async def __aexit__(self, *exc: object) -> None:
        await self.close()

    # -- one connection ---------------------------------------------------------------------
    async def _on_client(self, reader: asyncio.StreamReader, writer: asyncio.StreamWriter) -> None:
        # the connection runs in its own task so that close() can cancel it without asyncio
        # reporting the cancelled connection callback as an error
        task = asyncio.create_task(self._connection(reader, writer))
        self._handlers.add(task)
        try:
            (outcome,) = await asyncio.gather(task, return_exceptions=True)
        finally:
            self._handlers.discard(task)
        if isinstance(outcome, Exception):
            self.log.error("connection handling failed: %s", outcome, exc_info=outcome)

    async def _connection(self, reader: asyncio.StreamReader, writer: asyncio.StreamWriter) -> None:
        peer = _peer_of(writer)
        configure_socket(writer.get_extra_info("socket"))
        try:
            if not self.link.connect(peer):
                await self._goodbye(reader, writer, self.link.busy_message())
                return
            self.log.info("VIPLE connected from %s", peer)
            reason = "server stopping"
            try:
                reason = await self._serve(reader, writer)
            except Exception as err:
                reason = f"connection handling failed: {err}"
                self.log.error("%s: %s", peer, reason, exc_info=err)
            finally:
                self.link.disconnect(reason)
        finally:
            writer.close()

    async def _serve(self, reader: asyncio.StreamReader, writer: asyncio.StreamWriter) -> str:
        """Serve one program until it goes; why it ended."""
        link = self.link
        outbox = _Outbox(writer)
        pusher = asyncio.create_task(link.push_reports(outbox, self.config.report_ms / 1000))

        # an idle driver is cut off at once: nothing it has not read is worth sending
        def cut_off(task: asyncio.Task[str]) -> None:
            if not task.cancelled():
                writer.transport.abort()

        pusher.add_done_callback(cut_off)
        splitter = LineSplitter(self.config.max_line_bytes)
        try:
            while True:
                data = await reader.read(READ_SIZE)
                if pusher.done():
                    return _ended(pusher)
                if not data:
                    return "closed by VIPLE"
                link.heard()
                for line, err in _in_order(splitter, data):
                    if err is None:
                        await link.take(line, outbox)
                    else:
                        for reason in err.reasons:
                            link.reject(reason, link.received())
                        await link.pace()
                await link.pace()
        except OSError as err:
            return _ended(pusher) if pusher.done() else _reason(err)
        finally:
            pusher.cancel()
            await asyncio.gather(pusher, return_exceptions=True)

    async def _goodbye(
        self, reader: asyncio.StreamReader, writer: asyncio.StreamWriter, line: str
    ) -> None:
        """Send a last line and close gracefully, so that the peer gets to read it.

        Whatever the peer still sends is read and dropped for a moment: closing a socket with
        unread input would reset the connection and could destroy the line on its way.
        """
        with contextlib.suppress(Exception):
            writer.write(line.encode("utf-8") + b"\r\n")
            await asyncio.wait_for(writer.drain(), _GOODBYE_SECONDS)
            if writer.can_write_eof():
                writer.write_eof()
            await asyncio.wait_for(_drain_input(reader), _GOODBYE_SECONDS)


async def _drain_input(reader: asyncio.StreamReader) -> None:
    while await reader.read(READ_SIZE):
        pass


def _in_order(splitter: LineSplitter, data: bytes) -> Iterator[tuple[str, FrameError | None]]:
    """The lines of one read and the framing errors between them, in the order received.

    The splitter is fed one line at a time so that a dropped line's error keeps its place.
    """
    start = 0
    size = len(data)
    while start < size:
        end = data.find(b"\n", start)
        stop = size if end < 0 else end + 1
        try:
            lines = splitter.feed(data[start:stop])
        except FrameError as err:
            yield from ((line, None) for line in err.lines)
            yield "", err
        else:
            yield from ((line, None) for line in lines)
        start = stop


def _ended(task: asyncio.Task) -> str:
    """Why the report pusher ended: the idle rule's reason, or the error that stopped it."""
    if task.cancelled():
        return "server stopping"
    err = task.exception()
    if err is None:
        return str(task.result())
    return _reason(err) if isinstance(err, OSError) else f"report stream failed: {err}"


def _unavailable(err: OSError) -> bool:
    return err.errno in (
        errno.EADDRNOTAVAIL,
        errno.EAFNOSUPPORT,
        getattr(errno, "EPROTONOSUPPORT", -1),
    ) or isinstance(err, socket.gaierror)


def _reason(err: BaseException) -> str:
    if isinstance(err, OSError) and (err.errno or err.strerror):
        # asyncio wraps bind errors in a long message; the errno says it plainly
        code = None if isinstance(err, socket.gaierror) else err.errno
        text = os.strerror(code) if isinstance(code, int) and code > 0 else str(err.strerror)
        return text[:1].lower() + text[1:]
    return str(err) or type(err).__name__
