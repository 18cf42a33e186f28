"""The maze key (m): a maze file typed in a dialog goes on the station."""

from __future__ import annotations

from textual.pilot import Pilot
from textual.widgets import Input, Static

from workbench.labs.model import LABS_DIR
from workbench.sim.mazeio import load_maze
from workbench.tui.app import make_app
from workbench.tui.dialogs.path import PathDialog
from workbench.tui.screens.main import MainScreen
from workbench.wire.settings import AppSettings

from .support import run

RANKING = LABS_DIR.parent / "mazes" / "rank-local-best-wins.txt"


def test_m_loads_a_maze_file_onto_the_station_and_keeps_the_profile(tmp_path):
    app = make_app(AppSettings(paused=True, profile="unity"))

    async def body(pilot: Pilot) -> None:
        await pilot.press("m")
        dialog = app.screen
        assert isinstance(dialog, PathDialog)
        field = dialog.query_one("#path", Input)
        assert field.value.endswith("mazes/")  # the folder of the maze on the station
        field.value = str(RANKING)
        await pilot.press("enter")
        await pilot.pause()
        assert isinstance(app.screen, MainScreen)
        assert app.station.maze.same_layout(load_maze(RANKING))
        assert app.station.profile == "unity"
        assert app.maze_path == RANKING  # the editor saves there
        assert app.sub_title == f"{app.station.maze.name} (unity)"

    run(app, body)


def test_a_maze_that_cannot_be_read_is_shown_in_the_dialog(tmp_path):
    app = make_app(AppSettings(paused=True))

    async def body(pilot: Pilot) -> None:
        before = app.station.maze
        await pilot.press("m")
        app.screen.query_one("#path", Input).value = str(tmp_path / "missing.txt")
        await pilot.press("enter")
        await pilot.pause()
        dialog = app.screen
        assert isinstance(dialog, PathDialog)  # asked again, with the reason
        assert dialog.query_one("#path", Input).value == str(tmp_path / "missing.txt")
        assert "cannot read" in str(dialog.query_one("#error", Static).render())
        await pilot.press("escape")
        assert isinstance(app.screen, MainScreen)
        assert app.station.maze is before

    run(app, body)
