"""Bad files loaded from the app (m, g, l) show their error and the app keeps running."""

from __future__ import annotations

import pytest
from textual.pilot import Pilot
from textual.widgets import Input, Static

from tests.bad_files import SECRET, write_corpus
from workbench.labs import model
from workbench.tui.app import make_app
from workbench.tui.dialogs.algorithm import AlgorithmModal
from workbench.tui.dialogs.path import PathDialog
from workbench.tui.screens import labs as labs_screen
from workbench.tui.screens.main import MainScreen
from workbench.wire.settings import AppSettings

from .labs_support import lab_app, open_labs, text
from .support import run

MAZES = ["maze-deep-flow.txt", "maze-nul.txt", "maze-1000x1000.txt", "maze-1mb-line.txt"]
FSMS = ["fsm-expr-500-terms.yaml", "fsm-expr-500-nots.yaml", "fsm-nan-parameter.yaml",
        "fsm-alias-bomb.yaml", "fsm-non-utf8.yaml"]  # fmt: skip
LABS = ["lab-nul.yaml", "lab-non-utf8.yaml", "lab-deep-flow.yaml"]


@pytest.fixture(scope="module")
def corpus(tmp_path_factory):
    return {bad.filename: path for bad, path in write_corpus(tmp_path_factory.mktemp("bad"))}


def shown(widget: Static) -> str:
    return str(widget.render())


@pytest.mark.parametrize("name", MAZES)
def test_m_with_a_bad_maze_shows_the_error_and_keeps_the_maze(corpus, name):
    app = make_app(AppSettings(paused=True))
    path = corpus[name]

    async def body(pilot: Pilot) -> None:
        before = app.station.maze
        await pilot.press("m")
        app.screen.query_one("#path", Input).value = str(path)
        await pilot.press("enter")
        await pilot.pause()
        dialog = app.screen
        assert isinstance(dialog, PathDialog)
        error = shown(dialog.query_one("#error", Static))
        assert path.name in error and SECRET not in error
        await pilot.press("escape")
        assert isinstance(app.screen, MainScreen)
        assert app.station.maze is before and app.is_running

    run(app, body)


@pytest.mark.parametrize("name", FSMS)
def test_g_with_a_bad_fsm_file_shows_the_error_and_keeps_running(corpus, name):
    app = make_app(AppSettings(paused=True, profile="unity"))
    path = corpus[name]

    async def body(pilot: Pilot) -> None:
        await pilot.press("g")
        await pilot.pause()
        screen = app.screen
        assert isinstance(screen, AlgorithmModal)
        field = screen.query_one("#alg-path", Input)
        field.value = str(path)
        field.focus()
        await pilot.press("enter")
        await pilot.pause()
        error = shown(screen.query_one("#alg-error", Static))
        assert error.startswith(str(path)) and SECRET not in error
        assert app.station.algorithm is None and app.is_running

    run(app, body, size=(120, 40))


@pytest.mark.parametrize("name", LABS)
def test_l_with_a_bad_lab_file_shows_the_error_and_keeps_running(
    corpus, name, monkeypatch, tmp_path
):
    folder = tmp_path / "labs"
    folder.mkdir()
    (folder / name).write_bytes(corpus[name].read_bytes())
    monkeypatch.setattr(labs_screen, "load_labs", lambda: model.load_labs(folder))
    app = lab_app(tmp_path / "data")

    async def body(pilot: Pilot) -> None:
        screen = await open_labs(pilot)
        message = text(screen, "#labs-message")
        assert name in message and SECRET not in message
        await pilot.press("escape")
        assert isinstance(app.screen, MainScreen) and app.is_running

    run(app, body, size=(120, 40))
