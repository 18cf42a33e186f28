"""The PROXY protocol a load balancer (HAProxy's ``send-proxy-v2``) puts before the SSH
banner: the student's own address, so the login limits and the log see the student and not
the balancer.

Only connections from the trusted balancer addresses are read for a header; a header that is
missing, malformed or slow closes that connection. The header is read with exact sizes from
the raw socket, so no byte of the SSH stream behind it is taken, and the socket then goes to
asyncssh as an ordinary connection.
"""

from __future__ import annotations

import asyncio
import contextlib
import ipaddress
import socket
from collections.abc import Awaitable, Callable, Sequence
from dataclasses import dataclass
from typing import Any

import asyncssh

from workbench.door.networks import Network, trusted

#: the 12 bytes every version 2 header starts with
V2_SIGNATURE = b"\r\n\r\n\x00\r\nQUIT\n"
#: what follows the fixed 16 bytes of a version 2 header may be at most this long
V2_MAX_BODY = 512
#: the longest version 1 (text) header, its CRLF included
V1_MAX = 107


class ProxyHeaderError(ValueError):
    """The bytes are not a PROXY protocol header this server takes."""


@dataclass(frozen=True)
class ProxyHeader:
    """A whole header: ``client`` is the address it names, or None (an address family
    without one, or UNKNOWN: the balancer's own address stands); ``local`` for the LOCAL
    command, a balancer's own connection such as a health check."""

    client: str | None
    length: int
    local: bool = False


def bytes_wanted(data: bytes) -> int:
    """How many more bytes the header that starts with ``data`` needs (0: it is whole).

    Never more than the header still lacks, so reading exactly this many never takes a byte
    of what follows it. ProxyHeaderError once ``data`` cannot start a header.
    """
    if len(data) < len(V2_SIGNATURE):
        if not (V2_SIGNATURE.startswith(data) or b"PROXY ".startswith(data[:6])):
            raise ProxyHeaderError("it did not start with a PROXY protocol header")
        return len(V2_SIGNATURE) - len(data)  # the shortest text header is longer than this
    if data.startswith(V2_SIGNATURE):
        if len(data) < 16:
            return 16 - len(data)
        body = int.from_bytes(data[14:16], "big")
        if body > V2_MAX_BODY:
            raise ProxyHeaderError(f"its PROXY header claims {body} bytes (at most {V2_MAX_BODY})")
        return 16 + body - len(data)
    if not data.startswith(b"PROXY "):
        raise ProxyHeaderError("it did not start with a PROXY protocol header")
    if data.endswith(b"\r\n"):
        return 0
    if len(data) >= V1_MAX or b"\n" in data:
        raise ProxyHeaderError(f"its text PROXY header has no end within {V1_MAX} bytes")
    return 1


def parse_header(data: bytes) -> ProxyHeader:
    """The header ``data`` holds whole (as :func:`bytes_wanted` read it)."""
    if bytes_wanted(data) != 0:
        raise ProxyHeaderError("its PROXY header is cut short")
    if data.startswith(V2_SIGNATURE):
        return _parse_v2(data)
    return _parse_v1(data)


def _parse_v2(data: bytes) -> ProxyHeader:
    version, command = data[12] >> 4, data[12] & 0x0F
    if version != 2 or command not in (0, 1):
        raise ProxyHeaderError(f"its PROXY header has version {version} command {command}")
    if command == 0:
        return ProxyHeader(None, len(data), local=True)
    family, transport = data[13] >> 4, data[13] & 0x0F
    body = data[16:]
    if family in (1, 2):
        size = 4 if family == 1 else 16
        if transport != 1:
            raise ProxyHeaderError("its PROXY header is for UDP, not a TCP connection")
        if len(body) < 2 * size + 4:
            raise ProxyHeaderError("its PROXY header is too short for the addresses it names")
        address = ipaddress.ip_address(body[:size])
        return ProxyHeader(str(address), len(data))
    if family in (0, 3):  # unspecified, or a Unix socket: no address to take
        return ProxyHeader(None, len(data))
    raise ProxyHeaderError(f"its PROXY header has an unknown address family {family}")


def _parse_v1(data: bytes) -> ProxyHeader:
    try:
        words = data[:-2].decode("ascii").split(" ")
    except UnicodeDecodeError:
        raise ProxyHeaderError("its text PROXY header is not ASCII") from None
    if len(words) >= 2 and words[1] == "UNKNOWN":
        return ProxyHeader(None, len(data))
    if len(words) != 6 or words[1] not in ("TCP4", "TCP6"):
        raise ProxyHeaderError("its text PROXY header is not 'PROXY TCP4|TCP6 SRC DST SPORT DPORT'")
    try:
        source = ipaddress.ip_address(words[2])
        ipaddress.ip_address(words[3])
        ports = [int(p) for p in words[4:] if p.isdigit()]
    except ValueError:
        raise ProxyHeaderError("its text PROXY header names an address that is not one") from None
    if source.version != (4 if words[1] == "TCP4" else 6) or len(ports) != 2:
        raise ProxyHeaderError("its text PROXY header names addresses or ports that do not fit")
    if not all(0 <= p <= 65535 for p in ports):
        raise ProxyHeaderError("its text PROXY header names a port out of range")
    return ProxyHeader(str(source), len(data))


async def read_header(loop: asyncio.AbstractEventLoop, sock: socket.socket) -> ProxyHeader:
    """Read one header from the non-blocking ``sock``, exactly its bytes.

    EOFError if the connection closed before it sent anything (a balancer's TCP check)."""
    data = b""
    while wanted := bytes_wanted(data):
        chunk = await loop.sock_recv(sock, wanted)
        if not chunk:
            if not data:
                raise EOFError
            raise ProxyHeaderError("it closed in the middle of its PROXY header")
        data += chunk
    return parse_header(data)


class ProxyAcceptor:
    """Accepts TCP connections itself, reads the header on those from ``networks`` and hands
    each socket, with its client's address, to ``handoff``; ``refused(key, line)`` logs why a
    connection was closed."""

    def __init__(
        self,
        listeners: list[socket.socket],
        networks: Sequence[Network],
        handoff: Callable[[socket.socket, str], Awaitable[None]],
        refused: Callable[[str, str], None],
        deadline: float,
    ) -> None:
        self._listeners = listeners
        self._networks = tuple(networks)
        self._handoff = handoff
        self._refused = refused
        self._deadline = deadline
        self._tasks: set[asyncio.Task[None]] = set()
        self._accepting: list[asyncio.Task[None]] = []
        self._closed = asyncio.Event()

    def start(self) -> None:
        for listener in self._listeners:
            self._accepting.append(asyncio.create_task(self._accept(listener), name="ssh-accept"))

    def get_port(self) -> int:
        ports = {s.getsockname()[1] for s in self._listeners}
        return ports.pop() if len(ports) == 1 else 0

    def close(self) -> None:
        for task in (*self._accepting, *self._tasks):
            task.cancel()
        for listener in self._listeners:
            listener.close()
        self._closed.set()

    async def wait_closed(self) -> None:
        await self._closed.wait()
        await asyncio.gather(*self._accepting, *self._tasks, return_exceptions=True)

    async def _accept(self, listener: socket.socket) -> None:
        loop = asyncio.get_running_loop()
        while True:
            try:
                sock, peer = await loop.sock_accept(listener)
            except OSError as exc:  # out of files, or a connection reset before it was taken
                self._refused("accept failed", f"a connection could not be accepted: {exc}")
                await asyncio.sleep(0.5)
                continue
            sock.setblocking(False)
            task = asyncio.create_task(self._take(sock, str(peer[0])), name="ssh-proxy-header")
            self._tasks.add(task)
            task.add_done_callback(self._tasks.discard)

    async def _take(self, sock: socket.socket, peer: str) -> None:
        client = peer
        if trusted(peer, self._networks):
            try:
                async with asyncio.timeout(self._deadline):
                    header = await read_header(asyncio.get_running_loop(), sock)
                if header.local:  # the balancer's health check: it has nothing for SSH
                    raise EOFError
                client = header.client or peer
            except EOFError:  # a health check, or a connection given up: nothing to log
                sock.close()
                return
            except ProxyHeaderError as exc:
                self._refused(f"proxy header {peer}", f"connection from {peer} closed: {exc}")
                sock.close()
                return
            except TimeoutError:
                why = f"no PROXY header within {self._deadline:g} s"
                self._refused(f"proxy header {peer}", f"connection from {peer} closed: {why}")
                sock.close()
                return
            except OSError as exc:
                self._refused(f"proxy header {peer}", f"connection from {peer} lost: {exc}")
                sock.close()
                return
            except asyncio.CancelledError:
                sock.close()
                raise
        try:
            await self._handoff(sock, client)
        except OSError as exc:
            self._refused(f"handoff {peer}", f"connection from {client} lost: {exc}")
            with contextlib.suppress(OSError):
                sock.close()


async def open_listeners(bind: str, port: int, backlog: int = 100) -> list[socket.socket]:
    """Listening sockets on ``bind`` (all addresses when empty) and ``port`` (0: any, the
    same for every address), as asyncio's own servers open them."""
    loop = asyncio.get_running_loop()
    infos = await loop.getaddrinfo(
        bind or None, port, type=socket.SOCK_STREAM, flags=socket.AI_PASSIVE
    )
    listeners: list[socket.socket] = []
    seen = set()
    try:
        for family, kind, proto, _, address in infos:
            if (family, address) in seen:
                continue
            seen.add((family, address))
            sock = socket.socket(family, kind, proto)
            listeners.append(sock)
            sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
            if family == socket.AF_INET6:
                sock.setsockopt(socket.IPPROTO_IPV6, socket.IPV6_V6ONLY, 1)
            if port == 0 and len(listeners) > 1:
                address = (address[0], listeners[0].getsockname()[1], *address[2:])
            sock.bind(address)
            sock.listen(backlog)
            sock.setblocking(False)
    except BaseException:
        for sock in listeners:
            sock.close()
        raise
    return listeners


async def accept_behind_balancer(
    bind: str,
    port: int,
    networks: Sequence[Network],
    refused: Callable[[str, str], None],
    deadline: float,
    **ssh_options: Any,
) -> ProxyAcceptor:
    """Listen as ``asyncssh.create_server(**ssh_options)`` would, taking the client's address
    from the PROXY header on connections from ``networks``; asyncssh's connection has it as
    ``get_extra_info("client_address")``."""
    loop = asyncio.get_running_loop()
    options = await asyncssh.SSHServerConnectionOptions.construct(**ssh_options)

    async def handoff(sock: socket.socket, client: str) -> None:
        def connection() -> asyncssh.SSHServerConnection:
            conn = asyncssh.SSHServerConnection(loop, options)
            conn.set_extra_info(client_address=client)
            return conn

        await loop.create_connection(connection, sock=sock)

    acceptor = ProxyAcceptor(await open_listeners(bind, port), networks, handoff, refused, deadline)
    acceptor.start()
    return acceptor
