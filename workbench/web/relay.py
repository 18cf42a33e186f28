"""One student's app through the browser door, and the page attached to it.

The app is started as the SSH server starts one (:mod:`workbench.door.appproc`: forked from
the fork server with the session's settings, under the same memory cap) when the student's
first page connects. Its screen bytes go to the page attached, if any, through a
:class:`Page`, which sends them on in the order they came and stops reading the app while the
browser is behind. When the page goes (a reload, a dropped network) the app waits
:attr:`WebConfig.reattach_grace` seconds for a page to come back; the page that comes is
given the whole screen again (the app is told the page's size and asked to redraw). A second
page of the same student takes the app over and the first is told so.
"""

from __future__ import annotations

import asyncio
import contextlib
import json
import logging
import time
from collections.abc import Callable, Coroutine
from dataclasses import dataclass
from typing import Any, Protocol

from workbench.door.appproc import AppProcess
from workbench.door.leases import Lease

log = logging.getLogger("workbench.web")

#: a page's unsent screen bytes past which the app's output is no longer read (it waits)
BACKLOG_HIGH = 1 << 20
#: ... and below which it is read again
BACKLOG_LOW = 64 << 10


#: tasks started in the background, held until they are done
_BACKGROUND: set[asyncio.Task[Any]] = set()


def background(work: Coroutine[Any, Any, None], name: str | None = None) -> None:
    """Run ``work`` on its own, held until it is done."""
    task = asyncio.create_task(work, name=name)
    _BACKGROUND.add(task)
    task.add_done_callback(_BACKGROUND.discard)


class Socket(Protocol):
    """What a page's WebSocket offers the relay (aiohttp's ``WebSocketResponse``)."""

    async def send_bytes(self, data: bytes) -> None: ...

    async def send_str(self, data: str) -> None: ...

    async def close(self, *, code: int = ..., message: bytes = ...) -> bool: ...


@dataclass(frozen=True)
class Notice:
    """A line a page shows over its terminal (taken over, ended): JSON on the socket."""

    kind: str
    message: str

    def text(self) -> str:
        return json.dumps({"type": self.kind, "message": self.message})


TAKEN_OVER = Notice(
    "taken",
    "Your workbench was opened in another tab or window, and goes on there. "
    "Reload this page to take it back.",
)


class Page:
    """One open page: its socket and the screen bytes waiting to be sent to it."""

    def __init__(self, socket: Socket, address: str, on_drained: Callable[[], None]) -> None:
        self.socket = socket
        self.address = address
        self._on_drained = on_drained
        self._buffer = bytearray()
        self._wake = asyncio.Event()
        self._notices: list[Notice] = []
        self.closed = False
        self.sent = 0
        self._pump = asyncio.create_task(self._send(), name=f"web-page-{address}")

    @property
    def backlog(self) -> int:
        return len(self._buffer)

    def push(self, data: bytes) -> None:
        if not self.closed:
            self._buffer += data
            self._wake.set()

    def tell(self, notice: Notice) -> None:
        """Show ``notice`` once the screen bytes before it are sent."""
        if not self.closed:
            self._notices.append(notice)
            self._wake.set()

    async def _send(self) -> None:
        with contextlib.suppress(ConnectionError, RuntimeError, asyncio.CancelledError):
            while True:
                await self._wake.wait()
                self._wake.clear()
                if self._buffer:
                    chunk = bytes(self._buffer)
                    self._buffer.clear()
                    await self.socket.send_bytes(chunk)
                    self.sent += len(chunk)
                    self._on_drained()
                while self._notices:
                    await self.socket.send_str(self._notices.pop(0).text())

    async def close(self, notice: Notice | None = None) -> None:
        """Send what is waiting (and ``notice``), then close the socket."""
        if notice is not None:
            self.tell(notice)
        self.closed = True
        with contextlib.suppress(TimeoutError):
            await asyncio.wait_for(self._flushed(), 2.0)
        self._pump.cancel()
        with contextlib.suppress(Exception, asyncio.CancelledError):
            await self._pump
        with contextlib.suppress(Exception):
            await self.socket.close()

    async def _flushed(self) -> None:
        while self._buffer or self._notices:
            await asyncio.sleep(0.01)


class StudentApp:
    """A student's app and the page attached to it (None between a page and the next)."""

    def __init__(
        self,
        user: str,
        app: AppProcess,
        *,
        grace: float,
        resize_every: float,
        on_end: Callable[[StudentApp], Coroutine[Any, Any, None]],
        size: tuple[int, int] = (80, 24),
    ) -> None:
        self.user = user
        self.app = app
        self.grace = grace
        self.resize_every = resize_every
        self._on_end = on_end
        self.page: Page | None = None
        #: the size the app has (it starts at its first page's)
        self.size = size
        self._shown = False
        #: what the app wrote before its first page was attached
        self._early = bytearray()
        self.last_input = time.monotonic()
        self.started_at = time.monotonic()
        self._waiting: asyncio.TimerHandle | None = None
        self._resize: asyncio.TimerHandle | None = None
        self._resized_at = 0.0
        self._wanted = size
        self.ending = False
        #: the VIPLE ports the app was given (released when it ends)
        self.ports: tuple[int, ...] = ()
        #: its place among the user's sessions of every door (released when it ends)
        self.lease: Lease | None = None

    # -- pages -------------------------------------------------------------------------------
    def attach(self, socket: Socket, address: str, size: tuple[int, int]) -> Page:
        """``socket``'s page now shows the app; the page before it, if any, is told it was
        taken over. The app is given the page's size and draws its whole screen."""
        if self._waiting is not None:
            self._waiting.cancel()
            self._waiting = None
        before = self.page
        page = self.page = Page(socket, address, self._drained)
        first = not self._shown
        self._shown = True
        if before is not None:
            log.info("%s's workbench taken over by a page from %s", self.user, address)
            background(before.close(TAKEN_OVER))
        self.app.resume_output()
        if first:
            page.push(bytes(self._early))
            self._early.clear()
        if first and size == self.size:
            return page  # a new app draws its first screen at this size by itself
        self._redraw(size)
        return page

    def detach(self, page: Page) -> None:
        """``page`` went: if it was the one attached, the app waits for the next."""
        if page is not self.page:
            return
        self.page = None
        if not self.ending:
            loop = asyncio.get_running_loop()
            self._waiting = loop.call_later(self.grace, self._no_page_came)

    def _no_page_came(self) -> None:
        self._waiting = None
        if self.page is None and not self.ending:
            log.info("%s's page did not come back within %g s: ending the app", self.user,
                     self.grace)  # fmt: skip
            background(self._on_end(self))

    # -- the app's screen --------------------------------------------------------------------
    def output(self, data: bytes) -> None:
        page = self.page
        if page is None:
            if not self._shown and len(self._early) < BACKLOG_HIGH:
                self._early += data  # drawn before the first page came: it gets it all
            return  # nobody to show it to: the next page gets the screen redrawn
        page.push(data)
        if page.backlog > BACKLOG_HIGH:
            self.app.pause_output()

    def _drained(self) -> None:
        page = self.page
        if page is None or page.backlog < BACKLOG_LOW:
            self.app.resume_output()

    # -- the page's input --------------------------------------------------------------------
    def keys(self, data: bytes) -> None:
        self.last_input = time.monotonic()
        self.app.send_keys(data)

    def resize(self, size: tuple[int, int]) -> bool:
        """Pass a new size on, at most once per ``resize_every`` seconds (of a storm of
        resizes the app gets the latest); False when it came while one was held back."""
        self._wanted = size
        if self._resize is not None:
            return False
        wait = self._resized_at + self.resize_every - time.monotonic()
        if wait <= 0:
            self._pass_size_on()
        else:
            self._resize = asyncio.get_running_loop().call_later(wait, self._pass_size_on)
        return True

    def _pass_size_on(self) -> None:
        self._resize = None
        if self._wanted == self.size:
            return
        self._resized_at = time.monotonic()
        self.size = self._wanted
        self.app.resize(*self.size)

    def _redraw(self, size: tuple[int, int]) -> None:
        """Give a new page the app's whole screen, at the page's size."""
        if self._resize is not None:
            self._resize.cancel()
            self._resize = None
        if size != self.size:
            self._resized_at = time.monotonic()
            self.size = self._wanted = size
            self.app.resize(*size)
        self.app.redraw()

    # -- the end -----------------------------------------------------------------------------
    def cancel_timers(self) -> None:
        for handle in (self._waiting, self._resize):
            if handle is not None:
                handle.cancel()
        self._waiting = self._resize = None
