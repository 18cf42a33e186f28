"""Under a dialog the key bar and the message line offer only keys that work there: the
dialog's own and the app's priority ones (a dialog takes every other key), and the screen's
keys come back when it closes."""

from __future__ import annotations

import pytest
from textual.pilot import Pilot
from textual.screen import ModalScreen
from textual.widgets._footer import FooterKey

from workbench.tui.app import make_app
from workbench.tui.textual_private import bindings_of
from workbench.tui.widgets.key_bar import KeyBar
from workbench.wire.settings import AppSettings

from .support import run, screen_lines

#: how to reach each dialog a screen below stays visible under: keys to the screen, then the
#: key that opens the dialog
DIALOGS = {
    "sensor ports": ((), "o"),
    "load a maze": ((), "m"),
    "generate a maze": (("e",), "g"),
    "maze size": (("e",), "n"),
}


def bar_under(app) -> list[str]:
    """The keys drawn in the bottom row (by the key bar of the screen under the dialog)."""
    below = app.screen_stack[-2]
    return [k.key for k in below.query_one(KeyBar).query(FooterKey)]


@pytest.mark.parametrize("dialog", list(DIALOGS))
def test_the_key_bar_under_a_dialog_shows_only_keys_that_work(tmp_path, dialog):
    app = make_app(AppSettings(paused=True, student="ana", data_dir=tmp_path))
    to_screen, opens = DIALOGS[dialog]

    async def body(pilot: Pilot) -> None:
        await pilot.press(*to_screen)
        await pilot.pause()
        before = screen_lines(app)[-1]
        await pilot.press(opens)
        await pilot.pause()
        await pilot.pause()
        top = app.screen
        assert isinstance(top, ModalScreen), top
        works = {key for key, _b in top.active_bindings.items()}
        works |= {key for key, b in bindings_of(app) if b.priority}
        shown = bar_under(app)
        assert shown and set(shown) <= works, (shown, works)
        row = screen_lines(app)[-1]
        assert row != before and "esc" in row and "^q Quit" in row
        assert "? help" not in "\n".join(screen_lines(app)), "? does not reach the app here"
        await pilot.press("escape")
        await pilot.pause()
        await pilot.pause()
        assert screen_lines(app)[-1] == before

    run(app, body)
