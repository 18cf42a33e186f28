"""The pool of VIPLE ports the server hands to sessions (a TCP port and a WebSocket port each).

A port is handed out only when nothing else holds it on 127.0.0.1 at that moment. While the
server runs it remembers each user's last ports and offers them again, so a student who
reconnects can keep the same forwarding command.
"""

from __future__ import annotations

import socket
from collections.abc import Callable, Iterable

HOST = "127.0.0.1"
#: how many earlier port sets are remembered per user
REMEMBERED = 4


class PoolExhausted(Exception):
    """No free ports are left in the range."""


def parse_range(text: str) -> tuple[int, int]:
    """``"41000-41999"`` as ``(41000, 41999)``; ValueError with the reason otherwise."""
    first, sep, last = text.partition("-")
    try:
        low, high = int(first), int(last if sep else first)
    except ValueError:
        raise ValueError(f"{text!r} is not a port range like 41000-41999") from None
    if not 1024 <= low <= high <= 65535:
        raise ValueError(f"{text!r}: ports must be 1024-65535, the first not above the last")
    if high - low < 1:
        raise ValueError(f"{text!r}: a session needs two ports, so the range needs two")
    return low, high


def port_is_free(port: int, host: str = HOST) -> bool:
    """Whether a listening socket could be opened on ``host:port`` now."""
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as sock:
        # as asyncio's servers do: a port whose old connections linger in TIME_WAIT is free
        sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        try:
            sock.bind((host, port))
        except OSError:
            return False
    return True


class PortPool:
    """Ports ``first..last`` handed out in sets and given back when a session ends."""

    def __init__(
        self, first: int, last: int, is_free: Callable[[int], bool] = port_is_free
    ) -> None:
        self.first, self.last = first, last
        self._is_free = is_free
        self._in_use: set[int] = set()
        self._last: dict[str, list[tuple[int, ...]]] = {}
        self._cursor = first

    @property
    def in_use(self) -> frozenset[int]:
        return frozenset(self._in_use)

    def _usable(self, port: int, owned: frozenset[int]) -> bool:
        return port not in self._in_use and (port in owned or self._is_free(port))

    def allocate(self, user: str, count: int = 2, owned: Iterable[int] = ()) -> tuple[int, ...]:
        """``count`` free ports for ``user``: their last ones when free, else the next free.

        ``owned`` are ports that the user's own connections hold (a remote forward already
        listening, say): they count as free for this user.
        """
        owned = frozenset(owned)
        for ports in self._last.get(user, []):
            if len(ports) == count and all(self._usable(p, owned) for p in ports):
                return self._take(user, ports)
        chosen: list[int] = []
        size = self.last - self.first + 1
        for step in range(size):
            port = self.first + (self._cursor - self.first + step) % size
            if port in chosen or not self._usable(port, owned):
                continue
            chosen.append(port)
            if len(chosen) == count:
                self._cursor = port + 1 if port < self.last else self.first
                return self._take(user, tuple(chosen))
        raise PoolExhausted(
            f"no {count} free ports left in {self.first}-{self.last} "
            f"({len(self._in_use)} in use by sessions)"
        )

    def _take(self, user: str, ports: tuple[int, ...]) -> tuple[int, ...]:
        self._in_use.update(ports)
        remembered = [p for p in self._last.get(user, []) if p != ports]
        self._last[user] = [ports, *remembered][:REMEMBERED]
        return ports

    def release(self, ports: Iterable[int]) -> None:
        for port in ports:
            self._in_use.discard(port)
