"""Socket options for a VIPLE connection: TCP keepalive and a small, fixed send buffer.

Keepalive lets the system notice a peer whose machine vanished (a pulled cable, a laptop
closed) instead of keeping the connection, and with it the driver's seat, for hours. The
small send buffer keeps a program that stops reading visible: left alone, the system grows a
loopback connection's buffer to megabytes, hours of sensor reports.
"""

from __future__ import annotations

import contextlib
import socket

#: TCP keepalive: first probe after this many idle seconds, then every INTERVAL, give up after
#: COUNT unanswered probes (a vanished peer is noticed after about a minute)
KEEPALIVE_IDLE_S = 30
KEEPALIVE_INTERVAL_S = 10
KEEPALIVE_COUNT = 3
#: the system's send buffer for a connection (Linux doubles it for its bookkeeping). Set, so
#: that the system does not grow it to megabytes: a program that stops reading then shows as
#: writes backing up after a few hundred reports instead of tens of thousands
SOCKET_SEND_BUFFER = 16384


def configure_socket(sock: socket.socket | None) -> None:
    """Give a connection a fixed, small send buffer, and TCP keepalive with the probe timing
    where the platform lets us set it."""
    if sock is None:
        return
    with contextlib.suppress(OSError):
        sock.setsockopt(socket.SOL_SOCKET, socket.SO_SNDBUF, SOCKET_SEND_BUFFER)
    with contextlib.suppress(OSError):
        sock.setsockopt(socket.SOL_SOCKET, socket.SO_KEEPALIVE, 1)
    for name, value in (
        ("TCP_KEEPIDLE", KEEPALIVE_IDLE_S),
        ("TCP_KEEPALIVE", KEEPALIVE_IDLE_S),  # macOS calls the idle time this
        ("TCP_KEEPINTVL", KEEPALIVE_INTERVAL_S),
        ("TCP_KEEPCNT", KEEPALIVE_COUNT),
    ):
        option = getattr(socket, name, None)
        if option is not None:
            with contextlib.suppress(OSError):
                sock.setsockopt(socket.IPPROTO_TCP, option, value)
