"""The terminal driver of a served app: Textual's web driver, with an input thread that sleeps
while no key comes.

The lab server runs each session's app with Textual's web driver (packets over a pipe, see
``workbench/ssh/packets.py``). That driver's input thread wakes ten times a second, key or no
key, to look for a lone Escape whose sequence never finished: about a third of what an idle
session costs the server. :class:`SessionDriver` reads the same packets the same way, but its
thread waits for input without a time limit unless the key parser is waiting for the rest of an
escape sequence, and then only until the parser's own time limit. Ending the app wakes it at
once through a pipe of its own.
"""

from __future__ import annotations

import contextlib
import os
import selectors
import sys
from codecs import getincrementaldecoder
from collections.abc import Callable, Iterator

from textual import log
from textual._time import get_time
from textual._xterm_parser import XTermParser
from textual.drivers._byte_stream import ByteStream
from textual.drivers.web_driver import WebDriver, _ExitInput

#: how long to wait while the parser's own time limit cannot be read (Textual's interval)
FALLBACK_WAIT = 0.1
_UNKNOWN = object()


def parser_wait(parser: XTermParser) -> float | None:
    """How long the input thread may wait for input: until the parser's time limit for an
    unfinished escape sequence, or for ever (None) when it waits for none."""
    deadline = getattr(parser, "_timeout_time", _UNKNOWN)
    if deadline is _UNKNOWN or not isinstance(deadline, (float, int, type(None))):
        return FALLBACK_WAIT  # another Textual: wake as often as its own driver does
    if deadline is None:
        return None
    return max(0.0, deadline - get_time())


class InputWaiter:
    """Standard input as chunks of bytes (``b""`` when a wait ran out), read until closed."""

    def __init__(self, fileno: int | None = None) -> None:
        self._fileno = sys.__stdin__.fileno() if fileno is None else fileno
        self._wake_r, self._wake_w = os.pipe()
        self._selector = selectors.DefaultSelector()
        self._selector.register(self._fileno, selectors.EVENT_READ)
        self._selector.register(self._wake_r, selectors.EVENT_READ)
        self._closed = False
        #: how long the next wait may last (None: until input comes or the reader is closed)
        self.wait: Callable[[], float | None] = lambda: FALLBACK_WAIT

    def close(self) -> None:
        """Stop reading: a waiting thread wakes at once."""
        if self._closed:
            return
        self._closed = True
        with contextlib.suppress(OSError):
            os.write(self._wake_w, b"x")

    def __iter__(self) -> Iterator[bytes]:
        try:
            while not self._closed:
                for key, _ in self._selector.select(self.wait()):
                    if key.fd == self._wake_r:
                        return
                    data = os.read(self._fileno, 1024)
                    if not data:
                        return
                    yield data
                yield b""
        finally:
            self._selector.close()
            for fd in (self._wake_r, self._wake_w):
                with contextlib.suppress(OSError):
                    os.close(fd)


class SessionDriver(WebDriver):
    """Textual's web driver with an input thread that sleeps while no key comes."""

    def __init__(self, *args: object, **kwargs: object) -> None:
        super().__init__(*args, **kwargs)  # type: ignore[arg-type]
        selector = getattr(self._input_reader, "_selector", None)
        if selector is not None:
            selector.close()  # the web driver's own reader, never used
        self._input_reader = InputWaiter()  # type: ignore[assignment]

    def run_input_thread(self) -> None:
        """Wait for input and dispatch events (as the web driver does)."""
        reader = self._input_reader
        parser = XTermParser(debug=self._debug)
        assert isinstance(reader, InputWaiter)
        reader.wait = lambda: parser_wait(parser)
        decode = getincrementaldecoder("utf-8")().decode
        # the server sends a stream of bytes: the user's keys, and meta packets in band
        byte_stream = ByteStream()
        try:
            for data in reader:
                if data:
                    for packet_type, payload in byte_stream.feed(data):
                        if packet_type == "D":
                            for event in parser.feed(decode(payload)):
                                self.process_message(event)
                        else:
                            self._on_meta(packet_type, payload)
                for event in parser.tick():
                    self.process_message(event)
        except _ExitInput:
            pass
        except Exception:
            from traceback import format_exc

            log(format_exc())
        finally:
            reader.close()
