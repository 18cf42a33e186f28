"""The labs screen reads the saved work beside the app: a store that is slow to answer (a
course database that hangs) never holds up the keys, and the screen fills in once it does."""

from __future__ import annotations

import threading

from textual.pilot import Pilot
from textual.widgets import Input, OptionList

from tests.waiting import until
from workbench.labs.store.progress_rows import ProgressRows
from workbench.tui.screens.labs import LabsScreen
from workbench.tui.screens.main import MainScreen

from .labs_support import DRIVE, lab_app, open_exercise, text, try_answer
from .support import run


def test_the_keys_are_answered_while_the_saved_work_is_read_and_it_shows_once_read(
    tmp_path, monkeypatch
):
    data = tmp_path / "data"
    first = lab_app(data)

    async def work(pilot: Pilot) -> None:
        screen = await open_exercise(pilot, DRIVE)
        try_answer(screen, "tcp-port", "1350")
        await pilot.pause()

    run(first, work)
    answered = threading.Event()  # the store answers the read of the saved progress
    reading = threading.Event()
    progress = ProgressRows.of

    def slow_progress(rows: ProgressRows, student: str, lab: str | None = None) -> dict:
        reading.set()
        assert answered.wait(60), "the test never let the read go on"
        return progress(rows, student, lab)

    monkeypatch.setattr(ProgressRows, "of", slow_progress)
    again = lab_app(data)

    async def resume(pilot: Pilot) -> None:
        try:
            await pilot.press("l")
            screen = again.screen
            assert isinstance(screen, LabsScreen)
            await until(reading.is_set, "the saved progress being read")
            await pilot.pause()
            assert text(screen, "#labs-title") == "loading saved work..."
            # the screen's keys, while the read waits for the store
            listing = screen.query_one("#labs-list", OptionList)
            highlighted = listing.highlighted
            await pilot.press("a")
            assert text(screen, "#labs-message") == "loading saved work... a moment, please"
            await pilot.press("escape", "p")  # back to the maze, running
            assert isinstance(again.screen, MainScreen) and not again.station.paused
            frames = again.frames
            await pilot.press("w")
            await until(lambda: again.frames != frames, "a frame drawn after the key")
            await pilot.press("p", "l")
            assert again.screen is screen and screen.lab_progress.reading
            assert listing.highlighted == highlighted
        finally:
            answered.set()
        # the saved work arrives: the labs reopen where the student was, the answer kept
        await until(lambda: not screen.lab_progress.reading, "the saved work read")
        await pilot.pause()
        assert "Drive by wire" in text(screen, "#labs-title")
        assert listing.highlighted_option is not None
        assert listing.highlighted_option.id == DRIVE
        assert screen.query_one("#q-tcp-port", Input).value == "1350"
        assert text(screen, "#labs-message") == ""

    run(again, resume)
