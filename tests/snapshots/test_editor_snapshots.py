"""SVG snapshots of the maze editor, its dialogs, the runs screen and the replay screen.

80x24 (the lab terminal over SSH) and 120x40, ASCII and Unicode. Nothing runs on a clock:
runs are simulated to the end before the app starts, and replays are stepped by keys.
"""

from __future__ import annotations

from pathlib import Path

import pytest
from textual.pilot import Pilot

from tests.app.runs_support import runs_with_long_driver_names
from tests.app.support import Host, still
from tests.stations import run_to_exit
from workbench.control.station import LabStation
from workbench.sim.generate import generate
from workbench.sim.mazeio import load_maze
from workbench.tui.screens.editor import EditorScreen
from workbench.tui.screens.replay import ReplayScreen
from workbench.tui.screens.runs import RunsScreen

ROOT = Path(__file__).resolve().parents[2]
WEB = "mazes/web.txt"
SMALL = (80, 24)
LARGE = (120, 40)


def web_station(**kwargs) -> LabStation:
    return LabStation.open(load_maze(ROOT / WEB), "web", noise="off", **kwargs)


def press_then_still(*keys: str):
    async def run_before(pilot: Pilot) -> None:
        await pilot.pause()
        await pilot.press(*keys)
        await pilot.pause()
        still(pilot)

    return run_before


@pytest.fixture(scope="module")
def web_runs(tmp_path_factory) -> LabStation:
    """A station on the Web Simulator maze after two recorded algorithm runs."""
    station = web_station(record_dir=str(tmp_path_factory.mktemp("runs")))
    for name in ("web-wall-following", "two-distance-local-best"):
        station.select_algorithm(name)
        station.apply_algorithm_preset()
        run_to_exit(station)
    assert [r.ended for r in station.runs] == ["exit", "exit"]
    return station


# -- editor -----------------------------------------------------------------------------------
#: cursor from the start to the outer wall, opened: one problem in the list
EDIT_KEYS = ("left", "space", "up", "up", "right", "right", "x")


@pytest.mark.parametrize("unicode", [False, True], ids=["ascii", "unicode"])
def test_editor_80x24(snap_compare, unicode):
    app = Host(EditorScreen(web_station(), WEB, unicode=unicode))
    assert snap_compare(app, press=EDIT_KEYS, terminal_size=SMALL)


@pytest.mark.parametrize("unicode", [False, True], ids=["ascii", "unicode"])
def test_editor_generated_120x40(snap_compare, unicode):
    station = LabStation.open(generate(16, 16, 7), "unity", noise="off")
    app = Host(EditorScreen(station, None, unicode=unicode))
    assert snap_compare(app, press=("up", "up", "right", "space", "s"), terminal_size=LARGE)


def test_generate_dialog_80x24(snap_compare):
    app = Host(EditorScreen(web_station(), WEB))
    assert snap_compare(app, run_before=press_then_still("g"), terminal_size=SMALL)


def test_new_maze_dialog_with_an_error_80x24(snap_compare):
    app = Host(EditorScreen(web_station(), WEB))
    keys = ("n", "backspace", "backspace", "2", "enter")
    assert snap_compare(app, run_before=press_then_still(*keys), terminal_size=SMALL)


def test_unsaved_changes_prompt_80x24(snap_compare):
    app = Host(EditorScreen(web_station(), WEB, unicode=True))
    assert snap_compare(app, press=("right", "space", "escape"), terminal_size=SMALL)


# -- runs -------------------------------------------------------------------------------------
def test_runs_ascii_80x24(snap_compare, web_runs):
    assert snap_compare(Host(RunsScreen(web_runs, unicode=False)), terminal_size=SMALL)


def test_runs_unicode_120x40(snap_compare, web_runs):
    app = Host(RunsScreen(web_runs, unicode=True))
    assert snap_compare(app, press=("down",), terminal_size=LARGE)


# -- replay -----------------------------------------------------------------------------------
#: 400 ticks in (20 s of the run), then one back
REPLAY_KEYS = ("pagedown",) * 40 + ("left",)


@pytest.mark.parametrize("unicode", [False, True], ids=["ascii", "unicode"])
@pytest.mark.parametrize("size", [SMALL, LARGE], ids=["80x24", "120x40"])
def test_replay(snap_compare, web_runs, unicode, size):
    record = web_runs.runs[0].record
    app = Host(ReplayScreen(record, mazes=(web_runs.maze,), unicode=unicode))
    assert snap_compare(app, press=REPLAY_KEYS, terminal_size=size)


def test_replay_at_the_end_80x24(snap_compare, web_runs):
    record = web_runs.runs[1].record
    app = Host(ReplayScreen(record, mazes=(web_runs.maze,), unicode=False))
    assert snap_compare(app, press=("end",), terminal_size=SMALL)


@pytest.mark.parametrize("unicode", [False, True], ids=["ascii", "unicode"])
@pytest.mark.parametrize("press", [(), ("a",)], ids=["this-maze", "all-mazes"])
def test_runs_with_a_long_driver_name_80x24(snap_compare, tmp_path, unicode, press):
    """Every graded measure stands at 80 columns; the long names are shortened."""
    station = runs_with_long_driver_names(tmp_path)
    app = Host(RunsScreen(station, unicode=unicode))
    assert snap_compare(app, press=press, terminal_size=SMALL)
