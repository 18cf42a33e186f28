"""The terminal's keyboard, read live while a VIPLE program drives a robot (``viple run
--connect``).

In raw mode a terminal hands over each key as it is typed and nothing else: letters and digits
as themselves, space as a space, the arrows as escape sequences (``ESC [ A``, or ``ESC O A``
when the terminal is in application mode), Ctrl+C as the byte 3 (raw mode sends no signal).
:class:`KeyDecoder` turns those bytes into VIPLE's key names; :func:`raw_terminal` puts the
terminal in raw mode and always puts it back; :func:`attach_keyboard` hands the keys to a
running :class:`~workbench.viple.client.VipleClient`.

Two keys belong to the workbench and never reach the program: Ctrl+C and Esc both stop the
robot and end the run. VIPLE has no number for either, so no program can be waiting for them.
A lone Esc byte is told from the start of an arrow's sequence by a short wait
(:data:`ESCAPE_WAIT`): a terminal writes a whole sequence at once.
"""

from __future__ import annotations

import asyncio
import contextlib
import os
import termios
import tty
from collections.abc import Callable, Iterator

from workbench.program.keys import known_key
from workbench.viple.client import VipleClient

#: what :class:`KeyDecoder` gives for the two quit keys
QUIT = "quit"
#: how the quit keys are named to the user
QUIT_KEYS = "Esc or Ctrl+C"
CTRL_C = 0x03
ESC = 0x1B
#: seconds an Esc byte waits for the rest of a sequence before it counts as the Esc key
ESCAPE_WAIT = 0.1
#: the longest escape sequence kept while waiting for its end (a longer one is read to its end
#: and dropped)
MAX_SEQUENCE = 16
#: the last byte of an arrow's sequence, and the arrow
ARROWS = {ord("A"): "up", ord("B"): "down", ord("C"): "right", ord("D"): "left"}


class KeyDecoder:
    """Bytes from a terminal in raw mode as key names (``w``, ``7``, ``up``, ``space``) and
    :data:`QUIT`. Keys VIPLE has no number for (Enter, Tab, F-keys, punctuation) are left out;
    a capital letter is its key (Shift is not a key of its own)."""

    def __init__(self) -> None:
        self._pending = bytearray()

    @property
    def waiting(self) -> bool:
        """An escape sequence has begun and not ended: call :meth:`flush` if no byte follows
        within :data:`ESCAPE_WAIT`."""
        return bool(self._pending)

    def feed(self, data: bytes) -> list[str]:
        keys: list[str] = []
        for byte in data:
            if self._pending:
                self._sequence(byte, keys)
            elif byte == ESC:
                self._pending.append(byte)
            elif byte == CTRL_C:
                keys.append(QUIT)
            else:
                name = _plain_key(byte)
                if name is not None:
                    keys.append(name)
        return keys

    def flush(self) -> list[str]:
        """Nothing followed: a lone Esc is the quit key; an unfinished sequence is dropped."""
        lone = bytes(self._pending) == bytes((ESC,))
        self._pending.clear()
        return [QUIT] if lone else []

    def _sequence(self, byte: int, keys: list[str]) -> None:
        pending = self._pending
        if len(pending) == 1:  # just after ESC
            if byte in (ord("["), ord("O")):
                pending.append(byte)
                return
            pending.clear()
            if byte == ESC:  # Esc, then the start of something else
                keys.append(QUIT)
                pending.append(byte)
            elif byte == CTRL_C:
                keys.append(QUIT)
            # ESC and another key is Alt with that key: not a key VIPLE knows
            return
        if 0x40 <= byte <= 0x7E:  # the sequence's last byte
            overlong = len(pending) > MAX_SEQUENCE
            pending.clear()
            if byte in ARROWS and not overlong:
                keys.append(ARROWS[byte])
            return
        if len(pending) <= MAX_SEQUENCE:
            pending.append(byte)  # parameters (digits, ';')


def _plain_key(byte: int) -> str | None:
    return known_key(chr(byte)) if byte < 0x80 else None


@contextlib.contextmanager
def raw_terminal(fd: int) -> Iterator[None]:
    """The terminal at ``fd`` in raw mode for the ``with`` block; its settings come back when
    the block ends, however it ends (an exception, a signal that ends the run)."""
    saved = termios.tcgetattr(fd)
    try:
        tty.setraw(fd, termios.TCSANOW)
        yield
    finally:
        termios.tcsetattr(fd, termios.TCSADRAIN, saved)


def attach_keyboard(fd: int) -> Callable[[VipleClient], Callable[[], None]]:
    """What :func:`~workbench.viple.client.run_client` calls to let the terminal at ``fd``
    drive: each key goes to :meth:`VipleClient.press`, a quit key to :meth:`VipleClient.stop`."""

    def attach(client: VipleClient) -> Callable[[], None]:
        loop = asyncio.get_running_loop()
        decoder = KeyDecoder()
        timer: asyncio.TimerHandle | None = None

        def take(keys: list[str]) -> None:
            for key in keys:
                if key == QUIT:
                    client.stop(f"stopped from the keyboard ({QUIT_KEYS})")
                else:
                    client.press(key)

        def flush() -> None:
            nonlocal timer
            timer = None
            take(decoder.flush())

        def readable() -> None:
            nonlocal timer
            try:
                data = os.read(fd, 1024)
            except OSError:
                data = b""  # the terminal is gone
            if not data:
                loop.remove_reader(fd)
                return
            if timer is not None:
                timer.cancel()
                timer = None
            take(decoder.feed(data))
            if decoder.waiting:
                timer = loop.call_later(ESCAPE_WAIT, flush)

        loop.add_reader(fd, readable)

        def detach() -> None:
            loop.remove_reader(fd)
            if timer is not None:
                timer.cancel()

        return detach

    return attach
