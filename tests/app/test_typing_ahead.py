"""Keys typed ahead (over SSH a burst arrives in one read) land where the user meant them."""

from __future__ import annotations

from textual import events
from textual.pilot import Pilot
from textual.widgets import Input

from workbench.tui.app import make_app
from workbench.tui.dialogs.path import PathDialog
from workbench.tui.dialogs.size import SizeDialog
from workbench.wire.settings import AppSettings

from .support import run


def test_characters_typed_right_after_tab_go_into_the_next_field(tmp_path):
    app = make_app(AppSettings(paused=True, student="ana", data_dir=tmp_path))

    async def body(pilot: Pilot) -> None:
        app.push_screen(SizeDialog(10, 10))
        await pilot.pause()
        width = app.screen.query_one("#width", Input)
        height = app.screen.query_one("#height", Input)
        width.value = "30"
        # one burst, as a terminal delivers "\t12": nothing waits between the keys
        for key, char in (("tab", "\t"), ("1", "1"), ("2", "2"), ("shift+tab", None), ("7", "7")):
            app.post_message(events.Key(key, char))
        await pilot.pause()
        await pilot.pause()
        assert (width.value, height.value) == ("7", "12")

    run(app, body)


def test_editing_keys_typed_ahead_act_in_the_order_typed(tmp_path):
    app = make_app(AppSettings(paused=True, student="ana", data_dir=tmp_path))

    async def body(pilot: Pilot) -> None:
        app.push_screen(PathDialog("Load a maze", "help", value="maze3"))
        await pilot.pause()
        field = app.screen.query_one("#path", Input)
        # one burst: end (the text is selected on focus), backspace 5, then left x
        burst = [("end", None), ("backspace", "\x7f"), ("5", "5"), ("left", None), ("x", "x")]
        for key, char in burst:
            app.post_message(events.Key(key, char))
        await pilot.pause()
        await pilot.pause()
        assert field.value == "mazex5"
        for key, char in [("ctrl+u", "\x15"), ("a", "a"), ("b", "b"), ("backspace", "\x7f")]:
            app.post_message(events.Key(key, char))
        await pilot.pause()
        await pilot.pause()
        assert field.value == "a5"  # ctrl+u cleared what was left of the cursor

    run(app, body)
