"""Which SSH port forwards a user may open: only to the VIPLE ports of their own sessions.

- Local forwarding (``ssh -L 1350:localhost:TCP``): the destination must be this machine's
  loopback and the port the VIPLE TCP port of one of the user's live sessions.
- Remote forwarding (``ssh -R WS:localhost:8124``): the server may listen only on loopback, on
  the WebSocket port of one of the user's live sessions (the app connects there to reach the
  VIPLE on the student's computer).
"""

from __future__ import annotations

import asyncio
from collections.abc import Callable, Collection

import asyncssh
from asyncssh import SSHForwarder

LOOPBACK = frozenset({"localhost", "127.0.0.1", "::1"})
LISTEN_HOSTS = frozenset({"localhost", "127.0.0.1"})


def local_forward_refusal(host: str, port: int, own_tcp_ports: Collection[int]) -> str | None:
    """Why ``-L`` to ``host:port`` is refused, or None when it is allowed."""
    if host.lower() not in LOOPBACK:
        return f"destination {host}:{port} is not this server's loopback"
    return _not_own(port, own_tcp_ports, "VIPLE")


def remote_forward_refusal(host: str, port: int, own_ws_ports: Collection[int]) -> str | None:
    """Why ``-R`` listening on ``host:port`` is refused, or None when it is allowed."""
    if host.lower() not in LISTEN_HOSTS:
        return f"listening on {host or 'all addresses'!s}:{port} (only 127.0.0.1 is allowed)"
    return _not_own(port, own_ws_ports, "WebSocket")


def _not_own(port: int, own_ports: Collection[int], what: str) -> str | None:
    """Why ``port`` is not one of the user's own session ports of kind ``what``, or None."""
    if port in own_ports:
        return None
    if not own_ports:
        return f"port {port}: the user has no workbench session running"
    mine = ", ".join(str(p) for p in sorted(own_ports))
    return f"port {port} is not the {what} port of the user's sessions ({mine})"


class CountedForwarder(SSHForwarder):
    """The channel's side of a local forward, which gives its place among the connection's
    channels back when it closes."""

    def __init__(self, peer: SSHForwarder, release: Callable[[], None]) -> None:
        super().__init__(peer)
        self._release: Callable[[], None] | None = release

    def connection_lost(self, exc: Exception | None) -> None:
        if self._release is not None:
            release, self._release = self._release, None
            release()
        super().connection_lost(exc)


async def forward(host: str, port: int, release: Callable[[], None]) -> CountedForwarder:
    """Connect to ``host:port`` for a forward channel; ``release`` is called when the channel
    closes (or here, when the connection cannot be made)."""
    try:
        _, peer = await asyncio.get_running_loop().create_connection(SSHForwarder, host, port)
    except OSError as exc:
        release()
        raise asyncssh.ChannelOpenError(asyncssh.OPEN_CONNECT_FAILED, str(exc)) from None
    return CountedForwarder(peer, release)
