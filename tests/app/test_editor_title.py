"""The editor's title says truthfully whether the maze is saved, and where, at 80x24."""

from __future__ import annotations

from textual.pilot import Pilot
from textual.widgets import Input

from workbench.tui.app import make_app
from workbench.tui.screens.editor import EditorScreen
from workbench.wire.settings import AppSettings

from .support import run, screen_lines


def test_the_title_follows_saving_leaving_and_coming_back(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    app = make_app(AppSettings(paused=True, student="ana"))

    async def body(pilot: Pilot) -> None:
        await pilot.press("e")
        await pilot.pause()
        assert screen_lines(app)[0].strip() == "Maze editor: Unity default  [not saved yet]"
        await pilot.press("right", "space")  # a wall goes
        await pilot.pause()
        assert "(modified)" in screen_lines(app)[0]
        await pilot.press("ctrl+s")
        await pilot.pause()
        app.screen.query_one(Input).value = "mine.txt"
        await pilot.press("enter")
        await pilot.pause()
        assert screen_lines(app)[0].strip() == "Maze editor: Unity default  [mine.txt]"
        await pilot.press("escape")  # to the bench, with the saved maze on the robot
        await pilot.pause()
        await pilot.press("e")
        await pilot.pause()
        assert isinstance(app.screen, EditorScreen)
        assert screen_lines(app)[0].strip() == "Maze editor: Unity default  [mine.txt]"
        await pilot.press("space")
        await pilot.press("ctrl+s")  # saves where it came from, no question asked
        await pilot.pause()
        assert screen_lines(app)[0].strip() == "Maze editor: Unity default  [mine.txt]"
        assert (tmp_path / "mine.txt").read_text().count("\n") > 5

    run(app, body)
