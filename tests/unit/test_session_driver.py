"""The served app's input thread: it sleeps while no key comes, yet a lone Escape still arrives
and ending the app wakes it at once."""

from __future__ import annotations

import os
import threading
import time

from textual import events
from textual._xterm_parser import XTermParser

from workbench.tui.driver import InputWaiter, parser_wait


def read_in_thread(reader: InputWaiter) -> tuple[threading.Thread, list[bytes]]:
    got: list[bytes] = []
    thread = threading.Thread(target=lambda: got.extend(reader), daemon=True)
    thread.start()
    return thread, got


def test_an_idle_reader_does_not_wake_and_ends_at_once_when_closed():
    r, w = os.pipe()
    try:
        reader = InputWaiter(r)
        reader.wait = lambda: None  # no escape sequence pending: wait for input only
        thread, got = read_in_thread(reader)
        time.sleep(0.5)
        assert got == []  # Textual's own reader would have woken five times by now
        os.write(w, b"w")
        deadline = time.monotonic() + 5
        while got != [b"w", b""] and time.monotonic() < deadline:
            time.sleep(0.01)
        assert got == [b"w", b""]
        started = time.monotonic()
        reader.close()
        thread.join(5)
        assert not thread.is_alive() and time.monotonic() - started < 1.0
    finally:
        os.close(r)
        os.close(w)


def test_a_reader_whose_input_ends_stops():
    r, w = os.pipe()
    try:
        reader = InputWaiter(r)
        reader.wait = lambda: None
        thread, got = read_in_thread(reader)
        os.close(w)
        thread.join(5)
        assert not thread.is_alive() and got == []
    finally:
        os.close(r)


def test_the_wait_follows_the_parser_so_a_lone_escape_still_arrives():
    parser = XTermParser()
    assert parser_wait(parser) is None  # nothing pending: sleep until a key comes
    assert list(parser.feed("\x1b")) == []  # an Escape, or the start of a sequence?
    wait = parser_wait(parser)
    assert wait is not None and 0.0 < wait <= 0.2
    time.sleep(wait)
    keys = [e.key for e in parser.tick() if isinstance(e, events.Key)]
    assert keys == ["escape"]
    assert parser_wait(parser) is None


def test_a_key_sequence_leaves_nothing_pending():
    parser = XTermParser()
    keys = [e.key for e in parser.feed("\x1b[A") if isinstance(e, events.Key)]
    assert keys == ["up"] and parser_wait(parser) is None
