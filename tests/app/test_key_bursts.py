"""Keys that arrive together (over SSH a burst comes in one packet) each do what they do alone:
none is lost or overtaken when the next one moves the focus."""

from __future__ import annotations

import asyncio
from typing import ClassVar

from textual import events
from textual.app import ComposeResult
from textual.binding import Binding, BindingType
from textual.pilot import Pilot
from textual.widgets import Button, Checkbox, Input, Static

from workbench.labs.signoff.instructors import KdfParams, create_instructor
from workbench.tui.app import make_app
from workbench.tui.dialogs.signoff import SignoffModal
from workbench.tui.dialogs.size import SizeDialog
from workbench.tui.serving.ordered_keys import OrderedKeys
from workbench.wire.settings import AppSettings

from .labs_support import lab_app, open_exercise, signing_over
from .support import burst, run

FAST = KdfParams(n=2**10, r=8, p=1)  # cheap scrypt for tests only


def test_space_then_shift_tab_ticks_the_override_and_moves_back(tmp_path):
    data = tmp_path / "data"
    create_instructor(data, "Dr Chen", "correct horse battery", kdf=FAST)
    app = lab_app(data)

    async def body(pilot: Pilot) -> None:
        await open_exercise(pilot)
        await pilot.press("i")
        await pilot.pause()
        modal = app.screen
        assert isinstance(modal, SignoffModal)
        box = modal.query_one("#signoff-override", Checkbox)
        box.focus()
        await pilot.pause()
        await burst(pilot, ("space", " "), ("shift+tab", None))
        assert box.value is True
        assert modal.focused is modal.query_one("#signoff-note", Input)

    run(app, body)


def test_tick_back_and_sign_in_one_packet_signs_with_the_override(tmp_path):
    """ "\t \x1b[Z\r" from the passphrase: tab to the override, tick it, back to the note,
    enter: the sign-off sees the box ticked."""
    data = tmp_path / "data"
    create_instructor(data, "Dr Chen", "correct horse battery", kdf=FAST)
    app = lab_app(data)

    async def body(pilot: Pilot) -> None:
        await open_exercise(pilot)
        await pilot.press("i")
        await pilot.pause()
        modal = app.screen
        assert isinstance(modal, SignoffModal)
        modal.query_one("#signoff-passphrase", Input).value = "correct horse battery"
        modal.query_one("#signoff-note", Input).value = "checked at the station"
        modal.query_one("#signoff-note", Input).focus()
        await pilot.pause()
        await burst(pilot, ("tab", "\t"), ("space", " "), ("shift+tab", None), ("enter", "\r"))
        await signing_over(pilot, modal)
        assert modal.signed, str(modal.query_one("#signoff-status", Static).render())
        (row,) = app.store.signoffs.of()
        assert row.override and row.note == "checked at the station"

    run(app, body)


def test_shift_tab_then_space_ticks_the_box_the_focus_moved_to(tmp_path):
    data = tmp_path / "data"
    create_instructor(data, "Dr Chen", "correct horse battery", kdf=FAST)
    app = lab_app(data)

    async def body(pilot: Pilot) -> None:
        await open_exercise(pilot)
        await pilot.press("i")
        await pilot.pause()
        modal = app.screen
        sign = modal.query_one("#signoff-sign", Button)
        sign.focus()
        await pilot.pause()
        await burst(pilot, ("shift+tab", None), ("space", " "))
        box = modal.query_one("#signoff-override", Checkbox)
        assert box.value is True and modal.focused is box

    run(app, body)


def test_enter_on_a_button_then_tab_presses_that_button(tmp_path):
    app = make_app(AppSettings(paused=True, student="ana", data_dir=tmp_path))
    answers: list[tuple[int, int] | None] = []

    async def body(pilot: Pilot) -> None:
        app.push_screen(SizeDialog(10, 12), answers.append)
        await pilot.pause()
        app.screen.query_one("#ok", Button).focus()
        await pilot.pause()
        # enter on Create, tab on to Cancel: Create was pressed, Cancel was not
        await burst(pilot, ("enter", "\r"), ("tab", "\t"))
        assert answers == [(10, 12)]

    run(app, body)


def test_a_key_on_its_own_acts_once(tmp_path):
    data = tmp_path / "data"
    create_instructor(data, "Dr Chen", "correct horse battery", kdf=FAST)
    app = lab_app(data)

    async def body(pilot: Pilot) -> None:
        await open_exercise(pilot)
        await pilot.press("i")
        await pilot.pause()
        box = app.screen.query_one("#signoff-override", Checkbox)
        box.focus()
        await pilot.pause()
        await burst(pilot, ("space", " "))
        assert box.value is True  # toggled once (twice would leave it unticked)
        await burst(pilot, ("space", " "), ("space", " "), ("space", " "))
        assert box.value is False

    run(app, body)


class Stuck(Input):
    """A field whose handling of a key waits until it is let go."""

    def __init__(self, **kwargs) -> None:
        super().__init__(**kwargs)
        self.let_go = asyncio.Event()

    async def on_key(self, event: events.Key) -> None:
        event.stop()
        event.prevent_default()
        await self.let_go.wait()


class TwoFields(OrderedKeys):
    BINDINGS: ClassVar[list[BindingType]] = [Binding("tab", "focus_next", priority=True)]

    def compose(self) -> ComposeResult:
        yield Stuck(id="stuck")
        yield Input(id="stays")


def test_keys_waiting_behind_one_that_does_not_come_back_go_on_without_it():
    app = TwoFields()

    async def body(pilot: Pilot) -> None:
        stuck, stays = app.query_one(Stuck), app.query_one("#stays", Input)
        stuck.focus()
        await pilot.pause()
        # x is held up in the stuck field; tab, y and z wait for it, then go on without it
        # (the pilot's pause would wait for the stuck field too: the loop is watched instead)
        for key, char in (("x", "x"), ("tab", "\t"), ("y", "y"), ("z", "z")):
            app.post_message(events.Key(key, char))
        try:
            for _ in range(400):
                if stays.value == "yz":
                    break
                await asyncio.sleep(0.025)
            assert stays.value == "yz"
        finally:
            stuck.let_go.set()
        await pilot.pause()
        assert not app.keys_on_their_way

    run(app, body)
