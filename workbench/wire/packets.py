"""Textual's web-driver packets, the protocol between the server and an app process.

The app (run with Textual's web driver, ``workbench.tui.serving.terminal_driver``) writes
the line ``__GANGLION__`` on its standard output, then packets: one type byte (``D`` terminal
output, ``M`` JSON meta data, ``P`` binary-encoded data), a 4-byte big-endian length and the
payload.
The server writes packets of the same form to the app's standard input: ``D`` with the raw
bytes the user typed, ``M`` with ``{"type": "resize", ...}``, ``{"type": "redraw"}`` (write
the whole screen again, for a new terminal) or ``{"type": "quit"}``.
"""

from __future__ import annotations

import json
from typing import Any

GANGLION = b"__GANGLION__\n"
DATA, META, BINARY = b"D", b"M", b"P"
TYPES = (DATA, META, BINARY)
HEADER = 5
#: a packet larger than this is a broken stream, not a screen update
MAX_PAYLOAD = 64 * 1024 * 1024


class PacketError(ValueError):
    """The app's output does not follow the packet protocol."""


def encode(kind: bytes, payload: bytes) -> bytes:
    """One packet: type byte, 4-byte big-endian length, payload."""
    if kind not in TYPES:
        raise PacketError(f"unknown packet type {kind!r}")
    return kind + len(payload).to_bytes(4, "big") + payload


def data(payload: bytes) -> bytes:
    """Terminal input (or output) bytes as a ``D`` packet."""
    return encode(DATA, payload)


def meta(message: dict[str, Any]) -> bytes:
    """A JSON meta message as an ``M`` packet."""
    return encode(META, json.dumps(message, separators=(",", ":")).encode())


def resize(width: int, height: int) -> bytes:
    return meta({"type": "resize", "width": int(width), "height": int(height)})


def redraw() -> bytes:
    return meta({"type": "redraw"})


def quit_message() -> bytes:
    return meta({"type": "quit"})


class PacketReader:
    """Splits a stream into ``(type, payload)`` packets, fed in any chunks.

    Output before the ``__GANGLION__`` line (a warning printed by a library, say) is kept in
    :attr:`preamble` and not treated as packets.
    """

    def __init__(self, marked: bool = True) -> None:
        """``marked``: the stream starts with the ``__GANGLION__`` line (the app's output; the
        server's packets to the app have none)."""
        self._buffer = bytearray()
        self.started = not marked
        self.preamble = b""

    def feed(self, chunk: bytes) -> list[tuple[bytes, bytes]]:
        """The packets completed by ``chunk``, in order."""
        buffer = self._buffer
        if not buffer and self.started and len(chunk) >= HEADER:
            # the usual read: one whole packet (a typed key, a frame), nothing held from before
            size = int.from_bytes(chunk[1:HEADER], "big")
            if len(chunk) == HEADER + size and size <= MAX_PAYLOAD:
                kind = bytes(chunk[:1])
                if kind not in TYPES:
                    raise PacketError(f"unknown packet type {kind!r} in the app's output")
                return [(kind, bytes(chunk[HEADER:]))]
        packets: list[tuple[bytes, bytes]] = []
        buffer += chunk
        if not self.started:
            at = buffer.find(GANGLION)
            if at < 0:
                # keep only what could still be the start of the marker
                keep = len(GANGLION) - 1
                if len(buffer) > keep:
                    self.preamble += bytes(buffer[:-keep])
                    del buffer[:-keep]
                return packets
            self.preamble += bytes(buffer[:at])
            del buffer[: at + len(GANGLION)]
            self.started = True
        while len(buffer) >= HEADER:
            kind = bytes(buffer[:1])
            if kind not in TYPES:
                raise PacketError(f"unknown packet type {kind!r} in the app's output")
            size = int.from_bytes(buffer[1:HEADER], "big")
            if size > MAX_PAYLOAD:
                raise PacketError(f"a packet of {size} bytes in the app's output")
            if len(buffer) < HEADER + size:
                break
            packets.append((kind, bytes(buffer[HEADER : HEADER + size])))
            del buffer[: HEADER + size]
        return packets

    @property
    def pending(self) -> int:
        """Bytes received but not yet returned as a packet."""
        return len(self._buffer)
