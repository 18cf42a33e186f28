"""The terminal driver of a served app: Textual's web driver, reading its input on the app's
event loop instead of in a thread.

The lab server runs each session's app with Textual's web driver (packets over a pipe, see
``workbench/wire/packets.py``). That driver reads them in a thread of its own that wakes ten
times a second, key or no key (to look for a lone Escape whose sequence never finished), and hands
each key to the app's loop wrapped in a coroutine, a task and a pair of futures. With twenty
keys a second from a student driving, that thread and the hand-over were a fifth of what the app
cost. :class:`ServedTerminalDriver` reads the same packets the same way, on the event loop when the
pipe has data: nothing runs while no key comes, except a timer at the key parser's own time
limit while it waits for the rest of an escape sequence, and a key goes straight into the
app's message queue, in the order typed.

Typed characters (printable ASCII, outside an escape sequence and a bracketed paste) become
their keys without going through Textual's key parser, which logs a description of every key it
makes whether or not logging is on; the keys are the ones the parser makes for them
(:func:`plain_keys`). An app that can (:class:`TakesTypedKeys`) is offered each of them first,
and runs the action of a driving key at once, without a key event (``quick_keys.py``); once a
key goes the usual way, the rest of that text follows it, so keys stay in the order typed.

A synchronized update (the terminal's begin-update, the frame and end-update: three writes when
the student's terminal supports them) leaves the app as one packet, so the server reads and
forwards a frame in one piece.

A ``redraw`` meta packet (a browser's page that came back to its app) sets the terminal's modes
as at the start and writes the whole screen as it is (:meth:`ServedTerminalDriver.redraw`):
a resize to the size the app has already draws nothing.
"""

from __future__ import annotations

import asyncio
import contextlib
import os
import sys
from codecs import getincrementaldecoder
from functools import lru_cache
from typing import Any, Protocol, runtime_checkable

from textual import events, log, messages
from textual._ansi_sequences import SYNC_END, SYNC_START
from textual._time import get_time
from textual._xterm_parser import XTermParser
from textual.app import App
from textual.drivers.web_driver import WebDriver, _ExitInput

from workbench.wire.packets import DATA, GANGLION, PacketReader

from .key_budget import KeyBudget, dropped_message

#: how long to wait while the parser's own time limit cannot be read (Textual's interval)
FALLBACK_WAIT = 0.1
#: seconds a redraw waits while the app holds its frames back
REDRAW_WAIT = 0.02
#: the most bytes taken from the pipe at once
READ_SIZE = 65536
_UNKNOWN = object()
#: the bracketed paste's start and end (Textual's parser keeps typed text in a paste as the paste)
PASTE_START = "\x1b[200~"
PASTE_END = "\x1b[201~"


@lru_cache(maxsize=1)
def plain_keys() -> dict[str, tuple[str, str | None]]:
    """The key (name, character) Textual's parser makes for each printable ASCII character
    typed on its own."""
    table: dict[str, tuple[str, str | None]] = {}
    for character in map(chr, range(0x20, 0x7F)):
        made = [e for e in XTermParser().feed(character) if isinstance(e, events.Key)]
        if len(made) == 1:
            table[character] = (made[0].key, made[0].character)
    return table


def parser_wait(parser: XTermParser) -> float | None:
    """How long input may be waited for: until the parser's time limit for an unfinished
    escape sequence, or for ever (None) when it waits for none."""
    deadline = getattr(parser, "_timeout_time", _UNKNOWN)
    if deadline is _UNKNOWN or not isinstance(deadline, (float, int, type(None))):
        return FALLBACK_WAIT  # another Textual: wake as often as its own driver does
    if deadline is None:
        return None
    return max(0.0, deadline - get_time())


@runtime_checkable
class TakesTypedKeys(Protocol):
    """An app that may run a typed key's action at once, without a key event
    (``workbench/tui/serving/quick_keys.py``)."""

    def take_typed_key(self, key: str) -> bool:
        """Run what ``key`` does now and say so, or say no: it then comes as a key event."""
        ...


@runtime_checkable
class SaysThings(Protocol):
    """An app with a message line for the student."""

    def say(self, text: str) -> None: ...


#: seconds between a flood's first dropped key and the line that tells how many were
TELL_AFTER = 0.2


class LoopInput:
    """The server's packets on standard input, read on the event loop and handed to a driver.

    Stands in for the web driver's input thread (``start``) and its reader (``close``).
    """

    def __init__(self, driver: ServedTerminalDriver, fileno: int | None = None) -> None:
        self._driver = driver
        if fileno is None:
            if sys.__stdin__ is None:
                raise RuntimeError("a served app reads the server's packets on its standard input")
            fileno = sys.__stdin__.fileno()
        self.fileno = fileno
        self._parser = XTermParser(debug=driver._debug)
        self._decode = getincrementaldecoder("utf-8")().decode
        self._packets = PacketReader(marked=False)
        self._loop: asyncio.AbstractEventLoop | None = None
        self._escape: asyncio.TimerHandle | None = None
        self.reading = False
        self._plain = plain_keys()
        #: the app's quick way for a typed key, tried first (None: every key is a key event)
        app = driver._app
        self._take = app.take_typed_key if isinstance(app, TakesTypedKeys) else None
        #: inside a bracketed paste (the parser's text so far says so)
        self._pasting = False
        #: the end of the text the parser was last given, for a paste mark split over packets
        self._tail = ""
        #: typed keys past it are dropped, and the student told how many
        self.budget = KeyBudget()
        self._telling: asyncio.TimerHandle | None = None
        #: the parser was given text since its time limit was last looked at
        self._parser_fed = False

    def start(self) -> None:
        """Read from the next turn of the loop on: what the driver posted while starting (the
        terminal's size) reaches the app before the first key."""
        self._loop = loop = asyncio.get_running_loop()
        loop.call_soon(self._begin)

    def _begin(self) -> None:
        if self._loop is not None and not self.reading:
            self.reading = True
            self._loop.add_reader(self.fileno, self._read)

    def close(self) -> None:
        """Stop reading (the app ends, or the server closed the pipe)."""
        loop = self._loop
        if self._escape is not None:
            self._escape.cancel()
            self._escape = None
        if self._telling is not None:
            self._telling.cancel()
            self._telling = None
        if self.reading and loop is not None:
            self.reading = False
            with contextlib.suppress(Exception):
                loop.remove_reader(self.fileno)
        self._loop = None

    def _read(self) -> None:
        try:
            data = os.read(self.fileno, READ_SIZE)
        except (BlockingIOError, InterruptedError):
            return
        except OSError:
            data = b""
        if not data:  # the server is gone: nobody can type or see the screen any more
            self.close()
            self._driver.send_message(messages.ExitApp())
            return
        driver = self._driver
        try:
            for packet_type, payload in self._packets.feed(data):
                if packet_type == DATA:
                    self._typed(self._decode(payload))
                else:
                    driver._on_meta(packet_type.decode(), payload)
        except _ExitInput:
            self.close()
            return
        except Exception:
            from traceback import format_exc

            log(format_exc())
            self.close()
            return
        if self._escape is not None or self._parser_fed:
            self._tick()  # (plain keys alone leave the parser as it was: nothing to settle)

    def _typed(self, text: str) -> None:
        """Hand on the keys of some typed text: plain characters straight, anything else
        through Textual's parser (never with nothing: the parser takes that as the end)."""
        if not text:
            return
        driver = self._driver
        plain = self._plain
        parser = self._parser
        if (
            not self._pasting
            and self._escape is None  # (the parser waits for the rest of a sequence)
            and (text in plain or all(character in plain for character in text))
            and parser_wait(parser) is None
        ):
            text = self._within_budget(text)
            take = self._take
            for character in text:
                key, char = plain[character]
                if take is not None and take(key):
                    continue
                driver.process_message(events.Key(key, char))
                take = None  # the rest of the text follows that key the same way, in order
            self._tail = ""
            return
        self._parser_fed = True
        seen = self._tail + text
        started, ended = seen.rfind(PASTE_START), seen.rfind(PASTE_END)
        if started != ended:  # both -1 when neither is there
            self._pasting = started > ended
        self._tail = seen[-(len(PASTE_START) - 1) :]
        for event in parser.feed(text):
            if isinstance(event, events.Key) and not self.budget.take(1):
                self._dropped()
                continue
            driver.process_message(event)

    def _within_budget(self, text: str) -> str:
        """The first of ``text``'s keys the budget lets through."""
        allowed = self.budget.take(len(text))
        if allowed < len(text):
            self._dropped()
        return text[:allowed]

    def _dropped(self) -> None:
        """Keys were dropped: tell the student, once the flood has had a moment."""
        if self._telling is None and self._loop is not None:
            self._telling = self._loop.call_later(TELL_AFTER, self._tell)

    def _tell(self) -> None:
        self._telling = None
        count = self.budget.told()
        app = self._driver._app
        if count:
            log(f"{count} typed keys dropped")
            if isinstance(app, SaysThings):
                app.say(dropped_message(count))

    def _tick(self) -> None:
        """Hand on what the parser's time limit settled (a lone Escape), and wake again at its
        next limit while it waits for the rest of a sequence."""
        self._parser_fed = False
        if self._escape is not None:
            self._escape.cancel()
        self._escape = None
        for event in self._parser.tick():
            self._driver.process_message(event)
        wait = parser_wait(self._parser)
        if wait is not None and self.reading and self._loop is not None:
            self._escape = self._loop.call_later(wait, self._tick)


class ServedTerminalDriver(WebDriver):
    """Textual's web driver reading its input on the app's event loop (see the module)."""

    def __init__(self, *args: object, **kwargs: object) -> None:
        super().__init__(*args, **kwargs)  # type: ignore[arg-type]
        selector = getattr(self._input_reader, "_selector", None)
        if selector is not None:
            selector.close()  # the web driver's own reader, never used
        reading = LoopInput(self)
        # the web driver starts its input thread and closes its reader: both are the loop's
        self._key_thread = reading  # type: ignore[assignment]
        self._input_reader = reading  # type: ignore[assignment]
        #: the writes of a synchronized update so far (None: no update is open)
        self._frame: list[str] | None = None

    def on_meta(self, packet_type: str, payload: dict[str, object]) -> None:
        if packet_type == "redraw":
            self._app.call_later(self.redraw)
            return
        super().on_meta(packet_type, payload)

    def redraw(self) -> None:
        """Write the app's whole screen for a new terminal: the modes set at the start (the
        alternate screen, mouse reports, hidden cursor, bracketed paste), then every line.
        While the app holds its frames back (a batch of changes under way, no screen yet) it
        waits for them: a frame dropped then would leave the new terminal blank."""
        app = self._app
        if app._batch_count or not app._screen_stack or not app.screen.is_attached:
            app.set_timer(REDRAW_WAIT, self.redraw)
            return
        self.write("\x1b[?1049h")
        self._enable_mouse_support()
        self.write("\x1b[?25l")
        self._enable_bracketed_paste()
        screen = app.screen
        app._display(screen, screen._compositor.render_update(full=True))

    def take_terminal(self, fd: int, size: tuple[int, int]) -> None:
        """A spare app's terminal has come (``seat.py``): read and write on ``fd`` from now on
        (it becomes the standard input and output), announce the app on it as a start does,
        ask the terminal what a start asks, take its ``size`` and draw the whole screen."""
        reading = self._input_reader
        if isinstance(reading, LoopInput):
            reading.close()
        os.dup2(fd, 0)
        os.dup2(fd, 1)
        self._write(GANGLION)
        if isinstance(reading, LoopInput):
            reading.start()
        if size != self._size:
            self.on_meta("resize", {"width": size[0], "height": size[1]})
        self._request_terminal_sync_mode_support()
        self._app.call_later(self.redraw)

    def send_message(self, message: messages.Message) -> None:
        """Hand a message to the app (on its loop: straight into its queue)."""
        self._app.post_message(message)

    def write(self, data: str) -> None:
        """Write terminal output; a synchronized update is held until it ends and then written
        as one packet."""
        if data == SYNC_START:
            self._frame = [data]
            return
        frame = self._frame
        if frame is not None:
            frame.append(data)
            if data != SYNC_END:
                return
            self._frame = None
            data = "".join(frame)
        super().write(data)


def serves(app: App[Any]) -> bool:
    """Whether ``app`` runs in a served session (with :class:`ServedTerminalDriver`)."""
    return isinstance(app._driver, ServedTerminalDriver)
