"""The labs' set-up starts an exercise afresh and says what it changed, whole, at 80x24."""

from __future__ import annotations

from textual.pilot import Pilot

from .labs_support import lab_app, open_exercise, text
from .support import run, screen_lines

WALL = "unity-simulator/wall-following"


def test_set_up_puts_speed_algorithm_and_parameters_back_and_says_so(tmp_path):
    app = lab_app(tmp_path / "data", profile="erobotic")

    async def body(pilot: Pilot) -> None:
        station = app.station
        station.select_algorithm("one-distance-first")
        station.set_params(["right_blocked=50"])
        await pilot.press("+", "+", "+", "+")  # 2x, 4x, 10x, max
        assert station.pacer.speed is None
        screen = await open_exercise(pilot)  # drive by wire: the keys drive
        await pilot.press("a")
        await pilot.pause()
        assert station.pacer.speed == 1.0
        assert station.algorithm is None and station.overrides == {}
        said = text(screen, "#labs-message")
        assert "speed 1x (was max)" in said
        assert "algorithm none (was one-distance-first)" in said
        shown = " ".join(line.strip() for line in screen_lines(app)[-6:-1])
        assert "algorithm none (was one-distance-first)" in shown  # wrapped, not cut

    run(app, body)


def test_set_up_again_puts_the_starters_parameters_back(tmp_path):
    app = lab_app(tmp_path / "data")

    async def body(pilot: Pilot) -> None:
        screen = await open_exercise(pilot, WALL)
        await pilot.press("a")
        await pilot.pause()
        station = app.station
        starter = station.params()
        name = next(iter(starter))
        station.set_params([f"{name}={starter[name] + 1}"])
        await pilot.press("a")
        await pilot.pause()
        assert station.params() == starter
        assert f"parameters back to the starter's for {station.profile}" in text(
            screen, "#labs-message"
        )

    run(app, body)


def test_the_set_up_message_names_the_algorithm_once(tmp_path):
    app = lab_app(tmp_path / "data")

    async def body(pilot: Pilot) -> None:
        screen = await open_exercise(pilot, "maze-algorithms/erobotic-rules")
        await pilot.press("a")
        await pilot.pause()
        message = text(screen, "#labs-message")
        assert message.count("right-wall") == 1, message
        assert "algorithm right-wall (was none)" in message

    run(app, body)
