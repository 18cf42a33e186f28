"""Long messages at 80×24: the main screen's message line and the labs screen's course
database message are drawn whole, wrapped over the rows they need."""

from __future__ import annotations

import re

from textual.pilot import Pilot

from workbench.tui.app import make_app
from workbench.tui.screens.labs import UNREACHABLE
from workbench.tui.screens.main import MainScreen
from workbench.wire.settings import AppSettings

from .labs_support import lab_app, open_exercise, open_labs
from .support import run, screen_lines

#: what an algorithm that fails in a file kept deep in a student's folders may say
LONG = (
    "the algorithm stopped: /home/students/ana/lab work/week three/starters/"
    "web-two-distance-local-best-with-my-changes.yaml: state TurnedRight, rule 2: "
    "'RightDistance' is not set yet when 'when right > RightDistance + margin' is checked; "
    "set it in an activity of an earlier state (for example Forward) or check it after the "
    "turn (the robot is stopped where it was; r resets it)"
)


def drawn(pilot: Pilot, rows: int) -> str:
    """The words of the screen's last ``rows`` rows above the key bar, as one line."""
    return " ".join(" ".join(screen_lines(pilot.app)[-rows - 1 : -1]).split())


def test_a_long_message_on_the_main_screen_is_drawn_whole(tmp_path):
    app = make_app(AppSettings(paused=True, student="ana", data_dir=tmp_path / "data"))

    async def body(pilot: Pilot) -> None:
        screen = app.screen
        assert isinstance(screen, MainScreen)
        screen.say(LONG)
        await pilot.pause()
        await pilot.pause()
        assert LONG in drawn(pilot, 8)
        assert "driver: keys" in drawn(pilot, 14)  # the run panel stays in sight

    run(app, body)


def test_the_course_database_message_is_drawn_whole(tmp_path):
    # nothing listens on port 1: the database cannot be reached, the labs work on
    app = lab_app(tmp_path / "data", db="postgresql://ana@127.0.0.1:1/course")

    async def body(pilot: Pilot) -> None:
        await open_labs(pilot)
        said = drawn(pilot, 4)
        assert re.search(
            f"{UNREACHABLE}: your progress is kept here \\(\\d+ change\\(s\\)\\) and saved as "
            "soon as it is back$",
            said,
        ), said

    run(app, body)


def test_a_set_up_names_its_starter_by_the_file_alone(tmp_path):
    app = lab_app(tmp_path / "data")

    async def body(pilot: Pilot) -> None:
        screen = await open_exercise(pilot, "web-simulator/local-best-main")
        await pilot.press("a")
        await pilot.pause()
        said = drawn(pilot, 2)
        assert said == (
            "set up: web, web.txt, starter web-two-distance.yaml; "
            "algorithm starter-web-two-distance (was none)"
        ), said
        assert screen is app.screen

    run(app, body)
