"""The Web-Simulator role: connect to VIPLE's WebSocket server (``ws://HOST:8124/``).

In VIPLE's "WebSocket Server" connection type VIPLE listens and the robot connects. This
client keeps trying every second until VIPLE is up, and again after it goes away, logging
once per outage. One JSON object per text frame (several CRLF-separated objects in one frame
are accepted too); the reports are the same as the TCP role's: one pushed every
``report_ms`` and one in answer to each accepted command. Binary frames are rejected and
counted; a frame over the size limit closes the connection (and the client reconnects).

Keepalive pings go out every ``ping_interval_s``; a server that does not answer one within
``ping_timeout_s`` is taken as gone. As over TCP, reports are not queued behind a peer that
does not read, and a driver idle for ``idle_s`` loses the seat (see ``link``).
"""

from __future__ import annotations

import asyncio
import contextlib
import logging
from dataclasses import dataclass

from websockets.asyncio.client import ClientConnection, connect
from websockets.exceptions import ConnectionClosed, InvalidURI, WebSocketException
from websockets.frames import CLOSE_CODE_EXPLANATIONS, CloseCode
from websockets.uri import parse_uri

from workbench.sim.session import Session

from .codec import DEFAULT_MAX_LINE_BYTES, split_frame
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

DEFAULT_URL = "ws://localhost:8124/"
RETRY_SECONDS = 1.0
#: WebSocket keepalive: a ping this often, and the server must answer within the timeout
PING_INTERVAL_S = 20.0
PING_TIMEOUT_S = 20.0

log = logging.getLogger("workbench.viple.ws")


def check_ws_url(url: object) -> str:
    """The URL if it names a WebSocket server, else ``ValueError`` with the reason."""
    example = "e.g. ws://localhost:8124/"
    if not isinstance(url, str) or not url.strip():
        raise ValueError(f"WebSocket URL {url!r} is empty: give VIPLE's server, {example}")
    try:
        parse_uri(url.strip())
    except InvalidURI as err:
        raise ValueError(
            f"WebSocket URL {url!r} is not usable: {_uri_problem(err)} ({example})"
        ) from None
    except ValueError as err:
        raise ValueError(f"WebSocket URL {url!r} is not usable: {err} ({example})") from None
    return url.strip()


def _uri_problem(err: InvalidURI) -> str:
    return err.msg if getattr(err, "msg", "") else str(err)


@dataclass(frozen=True)
class WsConfig:
    url: str = DEFAULT_URL
    report_ms: int = REPORT_MS_DEFAULT
    max_message_bytes: int = DEFAULT_MAX_LINE_BYTES
    retry_seconds: float = RETRY_SECONDS
    #: seconds a driver may send nothing and read nothing before it loses the seat (None: never)
    idle_s: float | None = IDLE_S_DEFAULT
    ping_interval_s: float = PING_INTERVAL_S
    ping_timeout_s: float = PING_TIMEOUT_S

    def __post_init__(self) -> None:
        object.__setattr__(self, "url", check_ws_url(self.url))
        check_report_ms(self.report_ms)
        check_idle_s(self.idle_s)
        if not (self.ping_interval_s > 0 and self.ping_timeout_s > 0):
            raise ValueError("ping_interval_s and ping_timeout_s must be positive")
        if not self.max_message_bytes >= 1:
            raise ValueError("max_message_bytes must be at least 1")
        if not self.retry_seconds > 0:
            raise ValueError("retry_seconds must be positive")


class WsClient:
    """Connects ``robot`` (a session, or a station as its :class:`Cockpit`) to VIPLE's
    WebSocket server and keeps it connected."""

    def __init__(
        self,
        robot: Session | Cockpit,
        config: WsConfig | None = None,
        seat: Seat | None = None,
        logger: logging.Logger | None = None,
    ) -> None:
        self.config = config or WsConfig()
        self.log = logger or log
        self.link = Link(
            robot,
            "ws",
            address=self.config.url,
            seat=seat,
            logger=self.log,
            idle_s=self.config.idle_s,
        )
        self._task: asyncio.Task | None = None
        self._outage = False
        self._waiting = False

    @property
    def status(self) -> LinkStatus:
        return self.link.status

    async def start(self) -> None:
        """Start connecting in the background (returns at once)."""
        if self._task is None or self._task.done():
            self._task = asyncio.create_task(self.run(), name="viple-ws-client")

    async def close(self) -> None:
        """Disconnect (the robot stops) and stop retrying."""
        task, self._task = self._task, None
        if task is not None:
            task.cancel()
            await asyncio.gather(task, return_exceptions=True)

    async def __aenter__(self) -> WsClient:
        await self.start()
        return self

    async def __aexit__(self, *exc: object) -> None:
        await self.close()

    async def run(self) -> None:
        """Connect, serve, and reconnect for ever (until cancelled)."""
        url = self.config.url
        self.log.info("connecting to VIPLE's WebSocket server at %s (Web Simulator role)", url)
        while True:
            if self._seat_taken():
                await asyncio.sleep(self.config.retry_seconds)
                continue
            try:
                async with connect(
                    url,
                    proxy=None,
                    compression=None,
                    max_size=self.config.max_message_bytes,
                    open_timeout=max(2.0, self.config.retry_seconds),
                    ping_interval=self.config.ping_interval_s,
                    ping_timeout=self.config.ping_timeout_s,
                    close_timeout=1.0,
                ) as ws:
                    reason = await self._serve(ws)
                if reason is not None:
                    self.log.warning(
                        "VIPLE at %s went away (%s); reconnecting every %g s",
                        url,
                        reason,
                        self.config.retry_seconds,
                    )
                    self._outage = True
            except Exception as err:
                if not isinstance(err, OSError | TimeoutError | WebSocketException):
                    self.log.error("WebSocket connection failed: %s", err, exc_info=err)
                    self._outage = True
                elif not self._outage:
                    self.log.warning(
                        "VIPLE's WebSocket server at %s is not reachable (%s); trying again "
                        "every %g s",
                        url,
                        _describe(err),
                        self.config.retry_seconds,
                    )
                    self._outage = True
            await asyncio.sleep(self.config.retry_seconds)

    def _seat_taken(self) -> bool:
        holder = self.link.busy_with()
        taken = holder is not None and holder != self.config.url
        if taken and not self._waiting:
            self.log.info("%s is driving the robot; connecting to VIPLE when it is free", holder)
        self._waiting = taken
        return taken

    async def _serve(self, ws: ClientConnection) -> str | None:
        """Serve one connection; why it ended, or None when the robot was busy."""
        link = self.link
        url = self.config.url
        if not link.connect(url):
            return None
        self._outage = False
        self.log.info("connected to VIPLE at %s", url)
        configure_socket(ws.transport.get_extra_info("socket"))
        outbox = _Outbox(ws)
        pusher = asyncio.create_task(link.push_reports(outbox, self.config.report_ms / 1000))

        # an idle driver is cut off at once: nothing it has not read is worth sending
        def cut_off(task: asyncio.Task[str]) -> None:
            if not task.cancelled():
                ws.transport.abort()

        pusher.add_done_callback(cut_off)
        reason = "workbench stopping"
        try:
            while True:
                message = await ws.recv()
                link.heard()
                if isinstance(message, bytes):
                    link.reject(
                        f"binary frame of {len(message)} bytes rejected: VIPLE sends JSON "
                        "in text frames",
                        link.received(),
                    )
                else:
                    await link.handle(split_frame(message), outbox)
                await link.pace()
        except ConnectionClosed as closed:
            reason = _ended(pusher) if pusher.done() else self._closed_reason(closed)
            return reason
        except Exception as err:
            reason = f"connection handling failed: {err}"
            self.log.error("%s: %s", url, reason, exc_info=err)
            return reason
        finally:
            pusher.cancel()
            await asyncio.gather(pusher, return_exceptions=True)
            link.disconnect(reason)

    def _closed_reason(self, closed: ConnectionClosed) -> str:
        sent = closed.sent
        if sent is not None and sent.code == CloseCode.MESSAGE_TOO_BIG:
            why = f"frame longer than {self.config.max_message_bytes} bytes"
            self.link.reject(f"{why}; connection closed", self.link.received(), log=False)
            self.log.warning("%s: %s; connection closed", self.config.url, why)
            return why
        return _describe(closed)


class _Outbox:
    """A WebSocket connection's writing side: one text frame per report, never waiting."""

    def __init__(self, ws: ClientConnection) -> None:
        self.ws = ws

    def queued(self) -> int:
        return self.ws.transport.get_write_buffer_size()

    async def write(self, line: str) -> None:
        await self.ws.send(line)


def _ended(task: asyncio.Task) -> str:
    """Why the report pusher ended: the idle rule's reason, or the error that stopped it."""
    if task.cancelled():
        return "workbench stopping"
    err = task.exception()
    return str(task.result()) if err is None else _describe(err)


def _describe(err: BaseException) -> str:
    if isinstance(err, ConnectionClosed):
        frame = err.rcvd or err.sent
        if frame is None:
            return "connection lost"
        code = int(frame.code)
        meaning = frame.reason or CLOSE_CODE_EXPLANATIONS.get(code, "")
        who = "VIPLE" if err.rcvd is not None else "the workbench"
        return f"closed by {who} with code {code}{f': {meaning}' if meaning else ''}"
    if isinstance(err, OSError) and err.strerror:
        return err.strerror
    with contextlib.suppress(Exception):
        text = str(err)
        if text:
            return text
    return type(err).__name__
