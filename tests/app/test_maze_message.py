"""The message line names the maze on the station, and says when the robot keeps a profile
other than the one the maze file names."""

from __future__ import annotations

from textual.pilot import Pilot
from textual.widgets import Input

from workbench.files.bundled import MAZE_DIR
from workbench.labs.model import load_labs
from workbench.tui.app import make_app
from workbench.tui.widgets.message_bar import MessageBar
from workbench.wire.settings import AppSettings

from .labs_support import open_exercise
from .support import run, screen_lines

DRIVE = {lab.id: lab for lab in load_labs()}["unity-simulator"].exercise("drive-by-wire")


async def load(pilot: Pilot, path: str) -> None:
    await pilot.press("m")
    await pilot.pause()
    pilot.app.screen.query_one("#path", Input).value = path
    await pilot.press("enter")
    await pilot.pause()


def test_loading_the_erobotic_maze_under_unity_says_the_profile_stays(tmp_path):
    app = make_app(AppSettings(paused=True, data_dir=tmp_path / "data"))

    async def body(pilot: Pilot) -> None:
        assert app.station.profile == "unity"
        await load(pilot, str(MAZE_DIR / "erobotic.txt"))
        assert app.station.maze.name == "eRobotic lab maze"
        assert app.station.profile == "unity"  # the labs run this maze on the Unity robot
        said = " ".join(" ".join(screen_lines(app)[-4:]).split())
        assert "the robot is on eRobotic lab maze, still with the unity profile" in said
        assert "(the maze file names erobotic; --profile erobotic at start uses it)" in said
        await load(pilot, str(MAZE_DIR / "rank-wall-wins.txt"))  # made for unity: no note
        bar = app.screen.query_one(MessageBar)
        assert bar.message == "the robot is on Ranking - right wall wins"

    run(app, body)


def test_a_lab_set_up_on_another_maze_leaves_no_stale_maze_name(tmp_path):
    app = make_app(AppSettings(paused=True, data_dir=tmp_path / "data", student="ana"))

    async def body(pilot: Pilot) -> None:
        await load(pilot, str(MAZE_DIR / "erobotic.txt"))
        screen = await open_exercise(pilot, "unity-simulator/drive-by-wire")
        await pilot.press("a")
        await pilot.press("escape")
        await pilot.pause()
        assert app.station.maze.same_layout(DRIVE.setup.maze.maze)
        bar = app.screen.query_one(MessageBar)
        assert "eRobotic" not in bar.message
        assert bar.message == f"the robot is on {app.station.maze.name}"
        assert screen is not app.screen

    run(app, body)
