"""The app goes on when its run records cannot: a full disk, a file named ``runs`` in the
workspace. The clock keeps ticking, the keys keep driving, the message line says what happened,
and recording comes back."""

from __future__ import annotations

from pathlib import Path

from textual.pilot import Pilot

from tests.waiting import until
from workbench.files.workspace import workspace_folder
from workbench.sim.record import read_record
from workbench.tui.app import make_app
from workbench.tui.dialogs.path import PathDialog
from workbench.tui.screens.editor import EditorScreen
from workbench.wire.settings import AppSettings

from .support import run, said
from .test_workspace_app import type_path

ROOM = "---\nname: room\nprofile: erobotic\n---\n#######\n#.....#\n#..S..#\n#.....#\n#######\n"


def test_a_full_disk_leaves_the_app_driving_and_recording_comes_back(tmp_path, disk):
    maze = tmp_path / "room.txt"
    maze.write_text(ROOM)
    runs = tmp_path / "runs"
    app = make_app(AppSettings(maze, noise="off", record_dir=runs))
    station = app.station

    async def body(pilot: Pilot) -> None:
        await pilot.press("a")  # the robot spins: a run, recorded
        started = station.snapshot().time
        await until(lambda: station.snapshot().time > started + 1.5, "a second recorded")
        disk.full = True
        await until(lambda: "no room on the disk" in said(app), "the disk-full message")
        assert "the run goes on unrecorded" in said(app)
        full_at = station.snapshot().time
        await until(lambda: station.snapshot().time > full_at + 1, "the clock going on")
        heading = station.snapshot().pose.heading
        await pilot.press("d")  # the keys still drive
        await until(lambda: station.snapshot().pose.heading != heading, "the robot turning")
        disk.full = False
        await pilot.press("r", "a")  # a new run: recorded again
        await until(lambda: station.snapshot().time > 1.2, "the new run going")
        await pilot.press("r")
        await until(lambda: len(station.runs) == 2, "the second run ending")

    run(app, body)
    first, second = app.station.runs
    assert read_record(first.record).summary is None  # cut off where the disk filled
    assert read_record(second.record).summary is not None
    assert disk.refused > 0


def test_a_file_named_runs_is_moved_aside_on_the_first_drive_key(tmp_path):
    workspace = workspace_folder(tmp_path / "data", "ann")
    workspace.mkdir(parents=True)
    (workspace / "runs").write_text("a maze saved as ~/runs\n")
    app = make_app(
        AppSettings(paused=True, workspace=workspace, record_dir=workspace / "runs" / "20250101-1")
    )

    async def body(pilot: Pilot) -> None:
        await pilot.press("w")
        await until(lambda: "runs.taken-1" in said(app), "the moved-aside message")
        assert said(app).startswith("your file ~/runs was in the way of your run records")
        await pilot.press("n", "n", "space")

    run(app, body)
    assert (workspace / "runs.taken-1").read_text() == "a maze saved as ~/runs\n"
    assert list((workspace / "runs" / "20250101-1").glob("run-*.jsonl"))


def test_the_editor_will_not_save_a_maze_as_runs(tmp_path):
    workspace: Path = workspace_folder(tmp_path / "data", "ann")
    app = make_app(AppSettings(paused=True, workspace=workspace))

    async def body(pilot: Pilot) -> None:
        await pilot.press("e")
        editor = app.screen
        assert isinstance(editor, EditorScreen)
        await pilot.press("space", "ctrl+s")
        assert isinstance(app.screen, PathDialog)
        await type_path(pilot, "~/runs")
        assert isinstance(app.screen, PathDialog)
        assert "keeps your run records in: save under another name" in editor.status
        await type_path(pilot, "runs-maze.txt")
        assert app.screen is editor and not editor.dirty

    run(app, body)
    assert not (workspace / "runs").exists()
    assert (workspace / "runs-maze.txt").is_file()
