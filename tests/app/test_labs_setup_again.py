"""``a`` on an exercise whose attempt under way has work asks first, saying what would stop
counting; no leaves the attempt as it is, yes begins a new one. Without work it sets up at
once."""

from __future__ import annotations

from textual.pilot import Pilot

from workbench.tui.dialogs.confirm import ConfirmDialog
from workbench.tui.screens.labs import LabsScreen

from .labs_support import lab_app, open_exercise, text
from .support import run, screen_lines


def test_setting_up_again_over_work_in_progress_asks_first(tmp_path):
    app = lab_app(tmp_path / "data")
    station = app.station

    async def body(pilot: Pilot) -> None:
        await open_exercise(pilot)
        await pilot.press("a")
        await pilot.pause()
        assert not isinstance(app.screen, ConfirmDialog)  # nothing done yet: no question
        first = station.attempt
        assert first is not None
        await pilot.press("escape", "w", "d", "l")  # two drive keys on the main screen
        await pilot.pause()
        screen = app.screen
        assert isinstance(screen, LabsScreen)
        await pilot.press("a")
        await pilot.pause()
        assert isinstance(app.screen, ConfirmDialog)
        shown = " ".join(" ".join(screen_lines(app)).split())
        assert "Drive by wire is under way: 2 drive keys so far." in shown
        assert "stops counting for the" in shown and "not passed yet" in shown
        await pilot.press("n")
        await pilot.pause()
        assert app.screen is screen and station.attempt is first
        assert "the attempt under way goes on" in text(screen, "#labs-message")
        await pilot.press("a")
        await pilot.pause()
        await pilot.press("y")
        await pilot.pause()
        assert app.screen is screen
        assert station.attempt is not first and station.attempt.exercise == "drive-by-wire"
        assert text(screen, "#labs-message").startswith("set up: ")

    run(app, body)
