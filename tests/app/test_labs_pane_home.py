"""Back on the exercise list, the exercise pane shows its objectives again: after the student
scrolled down to answer a question and came back with shift+tab, or left the labs screen and
came back."""

from __future__ import annotations

from collections.abc import Callable

from textual.containers import VerticalScroll
from textual.pilot import Pilot
from textual.widgets import Input

from .labs_support import lab_app, open_exercise
from .support import run, screen_lines

ACTIVITIES = "unity-simulator/local-best-activities"


def pane_shows_objectives(app) -> bool:
    return any("[ ] the Unity sensors on port 1" in line for line in screen_lines(app))


async def until(pilot: Pilot, done: Callable[[], bool]) -> bool:
    """Pause until ``done()`` (the pane scrolls to a focused field after a refresh, which a
    loaded machine can put a few frames later), for at most 10 s."""
    for _ in range(200):
        if done():
            return True
        await pilot.pause(0.05)
    return done()


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
        down = await until(pilot, lambda: pane.scroll_y > 0 and not pane_shows_objectives(app))
        assert down, screen_lines(app)  # down at the question
        await pilot.press("shift+tab", "shift+tab")
        await pilot.pause()
        assert screen.focused is screen.query_one("#labs-list")
        assert await until(pilot, lambda: pane_shows_objectives(app)), screen_lines(app)
        first.focus()
        assert await until(pilot, lambda: not pane_shows_objectives(app)), screen_lines(app)
        await pilot.press("escape", "l")  # to the maze and back
        back = await until(pilot, lambda: app.screen is screen and pane_shows_objectives(app))
        assert back, screen_lines(app)

    run(app, body)
