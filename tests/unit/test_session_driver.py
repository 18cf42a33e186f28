"""The served app's input: read on the app's event loop (no thread), keys in the order typed,
a lone Escape still arrives, nothing runs while no key comes; a frame leaves as one packet."""

from __future__ import annotations

import asyncio
import contextlib
import os
import threading
import time
from collections.abc import AsyncIterator

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from textual import events, messages
from textual.drivers import web_driver

from tests.waiting import until
from workbench.tui.serving.terminal_driver import (
    SYNC_END,
    SYNC_START,
    LoopInput,
    ServedTerminalDriver,
    XTermParser,
    parser_wait,
    plain_keys,
)
from workbench.wire import packets


class UnusedReader:
    """Stands in for Textual's own input reader, which the served terminal driver never uses (it
    watches the test runner's standard input, which cannot be waited on here)."""

    def close(self) -> None:
        pass


@pytest.fixture(autouse=True)
def no_textual_reader(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(web_driver, "InputReader", UnusedReader)


class PostBox:
    """What the driver hands to the app, and on which thread."""

    def __init__(self) -> None:
        self.messages: list[object] = []
        self.threads: set[int] = set()

    def post_message(self, message: object) -> bool:
        self.messages.append(message)
        self.threads.add(threading.get_ident())
        return True

    def keys(self) -> list[str]:
        return [m.key for m in self.messages if isinstance(m, events.Key)]


async def started_driver(box: PostBox) -> tuple[ServedTerminalDriver, int]:
    """A driver reading a pipe of our own as its standard input; returns the pipe's write end."""
    driver = ServedTerminalDriver(box)  # type: ignore[arg-type]
    r, w = os.pipe()
    reading = LoopInput(driver, r)
    driver._key_thread = reading  # type: ignore[assignment]
    driver._input_reader = reading  # type: ignore[assignment]
    reading.start()
    await asyncio.sleep(0)  # it reads from the next turn of the loop on
    assert reading.reading
    return driver, w


@contextlib.asynccontextmanager
async def reading_driver() -> AsyncIterator[tuple[PostBox, ServedTerminalDriver, int]]:
    """A started driver, what it hands the app, and the write end of its input; closed after."""
    box = PostBox()
    driver, w = await started_driver(box)
    try:
        yield box, driver, w
    finally:
        driver._input_reader.close()
        os.close(w)


async def settle(box: PostBox, count: int) -> None:
    await until(lambda: len(box.messages) >= count, f"{count} messages to the app")


def test_keys_arrive_in_order_on_the_apps_thread_and_no_thread_reads():
    async def go() -> None:
        threads = threading.active_count()
        async with reading_driver() as (box, driver, w):
            assert threading.active_count() == threads  # no input thread
            os.write(w, packets.data(b"ww"))
            os.write(w, packets.data(b"a") + packets.data(b" d"))
            await settle(box, 5)
            assert box.keys() == ["w", "w", "a", "space", "d"]
            assert box.threads == {threading.get_ident()}
            # nothing pending: no timer waits to wake the loop while no key comes
            assert driver._input_reader._escape is None  # type: ignore[attr-defined]

    asyncio.run(go())


def test_a_lone_escape_arrives_at_the_parsers_time_limit():
    async def go() -> None:
        async with reading_driver() as (box, _, w):
            os.write(w, packets.data(b"\x1b"))
            await settle(box, 1)
            assert box.keys() == ["escape"]
            os.write(w, packets.data(b"\x1b[A"))  # a whole sequence is one key at once
            await settle(box, 2)
            assert box.keys() == ["escape", "up"]

    asyncio.run(go())


def test_plain_keys_leave_the_parser_alone_and_an_escape_still_gets_its_time_limit():
    """A driving key costs its read and its key: the parser's time limit is looked at only
    when the parser was given something (an Escape, a sequence) or waits for the rest of one."""

    async def go() -> None:
        async with reading_driver() as (box, driver, w):
            reading = driver._input_reader
            parser = reading._parser  # type: ignore[attr-defined]
            looked: list[int] = []
            tick = parser.tick

            def counted_tick():  # type: ignore[no-untyped-def]
                looked.append(1)
                return tick()

            parser.tick = counted_tick
            for key in b"wwad ":
                os.write(w, packets.data(bytes([key])))
                await settle(box, len(box.keys()) + 1)
            assert box.keys() == ["w", "w", "a", "d", "space"] and looked == []
            os.write(w, packets.data(b"\x1b"))
            await settle(box, 6)
            assert box.keys()[-1] == "escape" and len(looked) >= 2  # the read, then the limit
            assert reading._escape is None  # type: ignore[attr-defined]

    asyncio.run(go())


def test_meta_packets_reach_the_app_and_the_end_of_input_ends_it():
    async def go() -> None:
        box = PostBox()
        driver, w = await started_driver(box)
        os.write(w, packets.resize(100, 30) + packets.quit_message())
        await settle(box, 2)
        resize, leave = box.messages
        assert isinstance(resize, events.Resize) and resize.size == (100, 30)
        assert isinstance(leave, messages.ExitApp)
        os.close(w)
        reading = driver._input_reader
        await until(lambda: not reading.reading, "the reading stopped")  # type: ignore[attr-defined]
        # with the server gone (its end of the pipe closed) the app ends, saving as it ends
        assert isinstance(box.messages[-1], messages.ExitApp) and len(box.messages) == 3

    asyncio.run(go())


def test_a_synchronized_update_leaves_as_one_packet():
    async def go() -> None:
        r, w = os.pipe()
        try:
            driver = ServedTerminalDriver(PostBox())  # type: ignore[arg-type]
            driver._write = lambda data: os.write(w, data)
            driver.write(SYNC_START)
            driver.write("\x1b[3;5Hw ")
            driver.write("\x1b[24;1H")
            driver.write(SYNC_END)
            driver.write("plain")
            reader = packets.PacketReader()
            reader.feed(packets.GANGLION)
            got = reader.feed(os.read(r, 4096))
            assert got == [
                (packets.DATA, f"{SYNC_START}\x1b[3;5Hw \x1b[24;1H{SYNC_END}".encode()),
                (packets.DATA, b"plain"),
            ]
        finally:
            os.close(r)
            os.close(w)

    asyncio.run(go())


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


def test_typed_characters_make_the_keys_textuals_parser_makes():
    table = plain_keys()
    assert set(table) == {chr(c) for c in range(0x20, 0x7F)}
    for character, (key, typed) in table.items():
        made = [e for e in XTermParser().feed(character) if isinstance(e, events.Key)]
        assert [(e.key, e.character) for e in made] == [(key, typed)]
    assert table["w"] == ("w", "w") and table[" "] == ("space", " ")
    assert table["W"][1] == "W" and table["?"] == ("question_mark", "?")


def test_typed_text_after_an_escape_or_inside_a_paste_goes_through_the_parser():
    async def go() -> None:
        async with reading_driver() as (box, _, w):
            os.write(w, packets.data(b"w"))
            # a paste whose start mark is split over two packets, its text in a third
            os.write(w, packets.data(b"\x1b[20"))
            os.write(w, packets.data(b"0~"))
            os.write(w, packets.data(b"wasd "))
            os.write(w, packets.data(b"x\x1b[201~"))
            os.write(w, packets.data(b"d"))
            # an Alt+a: the plain "a" right after an Escape belongs to it
            os.write(w, packets.data(b"\x1b"))
            os.write(w, packets.data(b"a"))
            await settle(box, 4)
            got = [
                m.key if isinstance(m, events.Key) else ("paste", m.text)
                for m in box.messages
                if isinstance(m, events.Key | events.Paste)
            ]
            assert got == ["w", ("paste", "wasd x"), "d", "alt+a"]

    asyncio.run(go())


class Collected:
    """Stands in for the driver: what ``LoopInput`` hands it, in order."""

    _debug = False

    def __init__(self) -> None:
        self.made: list[object] = []
        self._app: object = None

    def process_message(self, message: object) -> None:
        self.made.append(message)


class QuickApp:
    """Stands in for an app that runs some typed keys at once (``take_typed_key``): what it
    takes goes in the same list, in order, as the key events the driver makes."""

    def __init__(self, made: list[object], takes: frozenset[str]) -> None:
        self.made, self.takes = made, takes

    def take_typed_key(self, key: str) -> bool:
        if key not in self.takes:
            return False
        self.made.append(("taken", key))
        return True


def described(messages_made: list[object]) -> list[tuple[str, object]]:
    return [
        ("key", (m.key, m.character)) if isinstance(m, events.Key) else ("paste", m.text)
        for m in messages_made
        if isinstance(m, events.Key | events.Paste)
    ]


def in_order(made: list[object]) -> list[tuple[str, object]]:
    """Keys (by name) and pastes in the order the app gets them, taken at once or as events."""
    return [
        ("key", m[1]) if isinstance(m, tuple) else ("key", m.key) if isinstance(m, events.Key)
        else ("paste", m.text)
        for m in made
        if isinstance(m, tuple | events.Key | events.Paste)
    ]  # fmt: skip


TYPED = st.lists(
    st.text(
        alphabet=st.sampled_from([*"wasd pq?A~[0129;", "\x1b", "\r", "\t", "\x7f", "é"]),
        max_size=12,
    )
    | st.sampled_from(["\x1b[200~", "\x1b[201~", "\x1b[A", "\x1b[<0;3;4M"]),
    max_size=12,
)


@settings(max_examples=300, deadline=None)
@given(TYPED)
def test_typed_text_makes_the_same_keys_as_textuals_parser_however_it_comes(chunks):
    """Whatever is typed, in whatever packets: the keys and pastes are the ones Textual's parser
    makes from the same packets (the plain characters only skip its work)."""
    ours = Collected()
    reading = LoopInput(ours, fileno=-1)  # type: ignore[arg-type]
    parser = XTermParser()
    theirs: list[object] = []
    for chunk in chunks:
        reading._typed(chunk)
        if chunk:  # (an empty packet is no input; the parser would take it as the end)
            theirs.extend(parser.feed(chunk))
    assert described(ours.made) == described(theirs)


@settings(max_examples=300, deadline=None)
@given(TYPED, st.frozensets(st.sampled_from(["w", "a", "d", "space", "p", "q"])))
def test_keys_an_app_takes_at_once_keep_their_place_among_the_others(chunks, takes):
    """An app that runs some keys at once gets them where they were typed among the key events
    (and pastes) the driver makes, and is never offered a key inside a paste or an escape
    sequence; within one packet, no key is offered once one before it became a key event."""
    ours = Collected()
    ours._app = QuickApp(ours.made, takes)
    reading = LoopInput(ours, fileno=-1)  # type: ignore[arg-type]
    parser = XTermParser()
    theirs: list[object] = []
    for chunk in chunks:
        before = len(ours.made)
        reading._typed(chunk)
        if chunk:
            theirs.extend(parser.feed(chunk))
        this_packet = ours.made[before:]
        events_at = [i for i, m in enumerate(this_packet) if isinstance(m, events.Key)]
        taken_at = [i for i, m in enumerate(this_packet) if isinstance(m, tuple)]
        assert not (events_at and taken_at and min(events_at) < max(taken_at))
    assert in_order(ours.made) == in_order(theirs)
