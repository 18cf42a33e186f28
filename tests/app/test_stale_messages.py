"""A message line that says how the station is clears once a later action made it untrue:
"paused" once something resumed the simulation, "lacks a sensor" once the sensors fit (each
of them set off by another screen or dialog than the one that said it)."""

from __future__ import annotations

from textual.pilot import Pilot

from .support import run, said
from .test_app_panels import click, unity_app


async def redrawn(pilot: Pilot) -> None:
    pilot.app.refresh_views()
    await pilot.pause()
    await pilot.pause()


def test_paused_clears_once_the_algorithm_dialog_resumed_the_simulation():
    app = unity_app()
    app.station.pacer.paused = False

    async def body(pilot: Pilot) -> None:
        await pilot.press("p")
        assert said(app) == "paused: n steps, p resumes"
        await pilot.press("g")
        await pilot.pause()
        await click(pilot, "#alg-pause")  # the dialog's Pause resumes
        assert not app.station.paused
        await pilot.press("escape")
        await redrawn(pilot)
        assert said(app) == ""

    run(app, body, size=(120, 40))


def test_lacks_a_sensor_clears_once_the_sensor_panel_fitted_them():
    app = unity_app()
    station = app.station
    station.select_algorithm("right-wall")
    station.apply_sensors([])

    async def body(pilot: Pilot) -> None:
        await pilot.press("x")
        assert said(app) == "the algorithm lacks a sensor: f fits the sensors it needs"
        await pilot.press("o")
        await pilot.pause()
        await click(pilot, "#preset-unity")  # the sensors right-wall reads
        await pilot.press("escape")
        await redrawn(pilot)
        assert station.missing_sensors() is None
        assert said(app) == ""

    run(app, body)
