"""A served student's app (``--workspace``): the maze, editor, algorithm and run-record dialogs
reach only the workspace and the bundled files; refusals say why and show nothing of the file."""

from __future__ import annotations

from pathlib import Path

from textual.pilot import Pilot
from textual.widgets import Input, Static

from workbench.files.workspace import BUNDLED, workspace_folder
from workbench.sim.mazeio import load_maze
from workbench.tui.app import make_app
from workbench.tui.dialogs.path import PathDialog
from workbench.tui.screens.editor import EditorScreen
from workbench.tui.screens.main import MainScreen
from workbench.tui.screens.runs import RunsScreen
from workbench.wire.settings import AppSettings

from .support import run

SECRET = "rivera:\n  password: scrypt$16384$8$1$c2FsdA$aGFzaA\n"
UNITY = BUNDLED[0] / "unity-default.txt"
SMALL = "#####\n#S  #\n# # #\n#  E#\n#####\n"


def served_app(tmp_path: Path):
    data = tmp_path / "data"
    data.mkdir()
    (data / "ssh-users.yaml").write_text(SECRET)
    workspace = workspace_folder(data, "ann")
    app = make_app(AppSettings(paused=True, workspace=workspace, data_dir=data, student="ann"))
    return app, data, app.station.files.workspace


def screen_text(app) -> str:
    return "\n".join(str(w.render()) for w in app.screen.query(Static))


async def type_path(pilot: Pilot, path: str) -> None:
    field = pilot.app.screen.query_one("#path", Input)
    field.value = path
    await pilot.press("enter")
    await pilot.pause()


def test_m_loads_from_the_workspace_and_refuses_the_server_s_files(tmp_path):
    app, data, workspace = served_app(tmp_path)
    (workspace / "mine.txt").write_text(SMALL)

    async def body(pilot: Pilot) -> None:
        before = app.station.maze
        await pilot.press("m")
        assert "your workspace, ~/" in screen_text(app)  # the dialog says where files are
        for outside in ("../../ssh-users.yaml", str(data / "ssh-users.yaml"), "~root/x"):
            await type_path(pilot, outside)
            assert isinstance(app.screen, PathDialog), outside  # asked again, with the reason
            error = str(app.screen.query_one("#error", Static).render())
            assert "outside your workspace" in error or "another user" in error
            assert "scrypt" not in screen_text(app) and "rivera" not in screen_text(app)
        assert app.station.maze is before
        await type_path(pilot, "mine.txt")  # a name alone is in the workspace
        assert isinstance(app.screen, MainScreen)
        assert app.station.maze.same_layout(load_maze(workspace / "mine.txt"))
        await pilot.press("m")
        assert app.screen.query_one("#path", Input).value == "~/"
        await type_path(pilot, str(UNITY))  # a bundled maze is readable
        assert isinstance(app.screen, MainScreen)
        assert app.station.maze.same_layout(load_maze(UNITY))

    run(app, body)
    assert (data / "ssh-users.yaml").read_text() == SECRET


def test_the_editor_saves_a_bundled_maze_only_as_a_copy_in_the_workspace(tmp_path):
    app, data, workspace = served_app(tmp_path)
    shipped = UNITY.read_bytes()
    database = data / "workbench.sqlite3"
    database.write_bytes(b"SQLite format 3\x00 the section's grades")

    async def body(pilot: Pilot) -> None:
        await pilot.press("e")
        editor = app.screen
        assert isinstance(editor, EditorScreen)
        await pilot.press("space", "ctrl+s")  # a change, then save: a bundled maze asks where
        assert isinstance(app.screen, PathDialog)
        for target, why in (
            (str(UNITY), "bundled file, kept as shipped"),
            ("../../workbench.sqlite3", "outside your workspace"),
            (str(database), "outside your workspace"),
        ):
            await type_path(pilot, target)
            assert isinstance(app.screen, PathDialog), target
            assert why in editor.status, editor.status
        await type_path(pilot, "my-unity.txt")
        assert app.screen is editor and not editor.dirty
        assert editor.status == "saved to ~/my-unity.txt"
        assert (workspace / "my-unity.txt").is_file()

    run(app, body)
    assert UNITY.read_bytes() == shipped
    assert database.read_bytes() == b"SQLite format 3\x00 the section's grades"


def test_g_loads_fsm_files_only_from_the_workspace(tmp_path):
    app, data, _ = served_app(tmp_path)

    async def body(pilot: Pilot) -> None:
        await pilot.press("g")
        field = app.screen.query_one("#alg-path", Input)
        assert field.placeholder == "~/my.yaml or ~/my.viple"
        field.value = str(data / "ssh-users.yaml")
        field.focus()
        await pilot.press("enter")
        await pilot.pause()
        error = str(app.screen.query_one("#alg-error", Static).render())
        assert "outside your workspace" in error
        assert "scrypt" not in screen_text(app)
        assert app.station.algorithm is None

    run(app, body)


def test_a_run_record_outside_the_workspace_is_not_opened(tmp_path):
    app, data, _ = served_app(tmp_path)

    async def body(pilot: Pilot) -> None:
        await pilot.press("R")
        runs = app.screen
        assert isinstance(runs, RunsScreen)
        await pilot.press("o")
        assert app.screen.query_one("#path", Input).value == "~/"
        await type_path(pilot, str(data / "ssh-users.yaml"))
        assert isinstance(app.screen, PathDialog)
        assert "outside your workspace" in runs.status
        assert "scrypt" not in screen_text(app)

    run(app, body)


def test_run_records_of_a_served_student_are_kept_in_the_workspace(tmp_path):
    data = tmp_path / "data"
    workspace = workspace_folder(data, "ann")
    app = make_app(
        AppSettings(paused=True, workspace=workspace, record_dir=str(workspace / "runs" / "1"))
    )

    async def body(pilot: Pilot) -> None:
        await pilot.press("w", "n", "n", "space")
        await pilot.pause()

    run(app, body)
    assert list((workspace / "runs" / "1").glob("run-*.jsonl"))
