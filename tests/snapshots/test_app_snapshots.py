"""SVG snapshots of every screen of the app at 80x24 and 120x40, in ASCII and Unicode.

The app is made paused and stepped a fixed number of physics steps, input cursors do not
blink, nothing is clicked (no hover or pressed-button effects) and nothing waits on the wall
clock, so the pictures are the same on every run.
"""

from __future__ import annotations

import pytest
from textual.pilot import Pilot
from textual.widgets import Input, Select

from tests.app.support import still
from workbench.tui.app import WorkbenchApp, make_app
from workbench.wire.settings import AppSettings

SIZES = {"80x24": (80, 24), "120x40": (120, 40)}
MODES = {"ascii": False, "unicode": True}
grid = pytest.mark.parametrize(
    ("size", "unicode"),
    [(SIZES[s], MODES[m]) for s in SIZES for m in MODES],
    ids=[f"{s}-{m}" for s in SIZES for m in MODES],
)


def app(unicode: bool, **kw) -> WorkbenchApp:
    return make_app(AppSettings(paused=True, unicode=unicode, **kw))


async def drive_a_little(pilot: Pilot) -> None:
    station = pilot.app.station
    await pilot.press("d")
    station.step(180)
    await pilot.press("w")
    station.step(120)
    await pilot.press("space")
    station.step(30)
    pilot.app.refresh_views()
    await pilot.pause()


async def run_right_wall(pilot: Pilot) -> None:
    station = pilot.app.station
    station.select_algorithm("right-wall")
    station.start()  # what x does; paused again before the clock can run it
    station.pacer.paused = True
    station.step(60 * 25)
    pilot.app.refresh_views()
    await pilot.pause()


@grid
def test_main_screen_driven_by_keys(snap_compare, size, unicode):
    assert snap_compare(app(unicode), terminal_size=size, run_before=drive_a_little)


@grid
def test_main_screen_with_an_algorithm_running(snap_compare, size, unicode):
    assert snap_compare(app(unicode), terminal_size=size, run_before=run_right_wall)


@grid
def test_sensor_ports_with_problems_marked(snap_compare, size, unicode):
    async def before(pilot: Pilot) -> None:
        await pilot.press("o")
        await pilot.pause()
        rows = list(pilot.app.screen.query(".row-port").results(Input))
        rows[1].value = "1"
        rows[2].value = "120"
        list(pilot.app.screen.query(".row-mount").results(Select))[2].value = "back"
        rows[2].focus()
        await pilot.press("enter")  # applies, as the Apply button does
        still(pilot)
        await pilot.pause()

    assert snap_compare(app(unicode), terminal_size=size, run_before=before)


@grid
def test_algorithm_selector_with_a_missing_sensor(snap_compare, size, unicode):
    async def before(pilot: Pilot) -> None:
        pilot.app.station.apply_preset("web-two-distance")
        pilot.app.station.select_algorithm("right-wall")
        await pilot.press("g")
        await pilot.pause()
        still(pilot)
        await pilot.pause()

    assert snap_compare(app(unicode), terminal_size=size, run_before=before)


@grid
def test_help_screen(snap_compare, size, unicode):
    assert snap_compare(app(unicode), terminal_size=size, press=["question_mark"])


@pytest.mark.parametrize("unicode", [False, True], ids=["ascii", "unicode"])
def test_too_small_terminal(snap_compare, unicode):
    assert snap_compare(app(unicode), terminal_size=(60, 20))


@grid
def test_main_screen_with_a_program_driving(snap_compare, size, unicode, tmp_path, monkeypatch):
    from tests.app.test_app_program import drive_by_wire
    from workbench.program.choice import choose_program

    monkeypatch.chdir(tmp_path)
    drive_by_wire(tmp_path)

    async def before(pilot: Pilot) -> None:
        station = pilot.app.station
        choose_program(station, "wire.viple")
        station.start()
        station.pacer.paused = True
        station.step(6)
        await pilot.press("w")
        station.step(30)
        await pilot.press("w")  # the key repeating: still held
        station.step(30)
        pilot.app.refresh_views()
        await pilot.pause()

    assert snap_compare(app(unicode), terminal_size=size, run_before=before)


@grid
def test_main_screen_with_every_key_going_to_the_program(
    snap_compare, size, unicode, tmp_path, monkeypatch
):
    from tests.app.test_app_program import drive_by_wire
    from workbench.program.choice import choose_program

    monkeypatch.chdir(tmp_path)
    drive_by_wire(tmp_path)

    async def before(pilot: Pilot) -> None:
        station = pilot.app.station
        choose_program(station, "wire.viple")
        station.start()
        station.pacer.paused = True
        station.step(6)
        await pilot.press("ctrl+k", "w")
        station.step(30)
        pilot.app.refresh_views()
        await pilot.pause()

    assert snap_compare(app(unicode), terminal_size=size, run_before=before)


@grid
def test_algorithm_dialog_with_a_bad_program(snap_compare, size, unicode, tmp_path, monkeypatch):
    from tests.app.test_app_program import bad_program

    monkeypatch.chdir(tmp_path)
    bad_program(tmp_path)

    async def before(pilot: Pilot) -> None:
        await pilot.press("g")
        await pilot.pause()
        pilot.app.screen.query_one("#alg-path", Input).value = "bad.viple"
        await pilot.app.screen.choose("bad.viple")
        still(pilot)
        await pilot.pause()

    assert snap_compare(app(unicode), terminal_size=size, run_before=before)
