"""Back on the exercise list, the exercise pane shows its objectives again: after the student
scrolled down to answer a question and came back with shift+tab, or left the labs screen and
came back."""

from __future__ import annotations

from textual.containers import VerticalScroll
from textual.pilot import Pilot
from textual.widgets import Input

from tests.waiting import until

from .labs_support import lab_app, open_exercise
from .support import run, screen_lines

ACTIVITIES = "unity-simulator/local-best-activities"


def pane_shows_objectives(app) -> bool:
    return any("[ ] the Unity sensors on port 1" in line for line in screen_lines(app))


def test_the_pane_returns_to_the_objectives(tmp_path):
    app = lab_app(tmp_path / "data")

    async def body(pilot: Pilot) -> None:
        screen = await open_exercise(pilot, ACTIVITIES)
        pane = screen.query_one("#labs-scroll", VerticalScroll)
        assert pane_shows_objectives(app)
        first = screen.query(Input).first()
        first.focus()
        await pilot.pause()
        await pilot.press(*"180")
        # the pane scrolls to the focused field a refresh or two later
        await until(lambda: pane.scroll_y > 0 and not pane_shows_objectives(app),
                    "the pane down at the question")  # fmt: skip
        await pilot.press("shift+tab", "shift+tab")
        await pilot.pause()
        assert screen.focused is screen.query_one("#labs-list")
        await until(lambda: pane_shows_objectives(app), "the objectives back on the list")
        first.focus()
        await until(lambda: not pane_shows_objectives(app), "the pane down at the field again")
        await pilot.press("escape", "l")  # to the maze and back
        await until(lambda: app.screen is screen and pane_shows_objectives(app),
                    "the objectives shown on coming back to the labs")  # fmt: skip

    run(app, body)
