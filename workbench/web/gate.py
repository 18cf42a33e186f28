"""The browser door's connections that have not yet sent a whole request, held to the login
rules of :mod:`workbench.door.logins` (the same caps and early drop as the SSH server's
connections that have not logged in).

A connection is let in by the :class:`~workbench.door.logins.ConnectionGate` when it opens
(capped in all and per source, dropped at random past the start, the oldest past the grace
making room, a source whose connections sit on their places refused for a while) and leaves
it with its first whole request: a browser sends one at once, so only connections that hold a
socket without asking for anything (a slow header, an idle socket) stay counted, and those
are closed after the login timeout. A request is then answered by its own rules (a login, a
form token, a page's WebSocket needing both); an idle keep-alive connection is closed after
the same timeout by aiohttp. Connections from a trusted proxy are not counted: the proxy
keeps its own limits and all its students share its address.
"""

from __future__ import annotations

import asyncio
import logging
from collections.abc import Callable, Sequence
from typing import Any

from aiohttp import web

from workbench.door.logins import ConnectionGate
from workbench.door.networks import Network, trusted

log = logging.getLogger("workbench.web")

Say = Callable[[str, str], None]


class RequestGate:
    """Counts an aiohttp server's connections until their first request (see the module)."""

    def __init__(
        self,
        gate: ConnectionGate[Any],
        timeout: float,
        proxies: Sequence[Network],
        say: Say,
    ) -> None:
        self.gate = gate
        self.timeout = timeout
        self.proxies = proxies
        self._say = say
        self._waiting: dict[Any, asyncio.TimerHandle] = {}

    def watch(self, server: web.Server) -> None:
        """Count ``server``'s connections from now on."""
        made, lost = server.connection_made, server.connection_lost

        def connection_made(handler: Any, transport: asyncio.Transport) -> None:
            made(handler, transport)
            self._opened(handler, transport)

        def connection_lost(handler: Any, exc: BaseException | None) -> None:
            self._closed(handler)
            lost(handler, exc)

        server.connection_made = connection_made  # type: ignore[method-assign]
        server.connection_lost = connection_lost  # type: ignore[method-assign,assignment]

    def _opened(self, handler: Any, transport: asyncio.Transport) -> None:
        peer = transport.get_extra_info("peername")
        address = str(peer[0]) if peer else "unknown"
        if self.proxies and trusted(address, self.proxies):
            return
        admission = self.gate.admit(handler, address)
        evicted = admission.evicted
        if evicted is not None:
            self._end(evicted.key)
            self._say(
                f"made room {evicted.source}",
                f"connection from {evicted.source} closed after {evicted.held:.0f} s without "
                "a request, to make room for a new one",
            )
        if admission.refused is not None:
            self._say(f"gate {address}", f"connection refused: from {address}: "
                      f"{admission.refused}")  # fmt: skip
            self.gate.settled(handler, logged_in=True)  # it was never let in
            transport.close()
            return
        loop = asyncio.get_running_loop()
        self._waiting[handler] = loop.call_later(self.timeout, self._timed_out, handler, address)

    def asked(self, request: web.Request) -> None:
        """The connection of ``request`` sent a whole request: it no longer waits at the
        gate."""
        handler = request.protocol
        timer = self._waiting.pop(handler, None)
        if timer is not None:
            timer.cancel()
            self.gate.settled(handler, logged_in=True)

    def _timed_out(self, handler: Any, address: str) -> None:
        if self._waiting.pop(handler, None) is None:
            return
        self._say(f"timeout {address}", f"connection from {address} closed: no request "
                  f"within {self.timeout:g} s")  # fmt: skip
        if self.gate.settled(handler, logged_in=False):
            self._say(f"penalty {address}", f"connections from {address} refused for a "
                      "while: they held places without a request")  # fmt: skip
        handler.force_close()

    def _end(self, handler: Any) -> None:
        timer = self._waiting.pop(handler, None)
        if timer is not None:
            timer.cancel()
        handler.force_close()

    def _closed(self, handler: Any) -> None:
        timer = self._waiting.pop(handler, None)
        if timer is not None:
            timer.cancel()
            self.gate.settled(handler, logged_in=False)
