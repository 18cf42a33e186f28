"""The editor keeps the workspace's write rules as the file server does (issue 37): nothing in
~/runs is written but by the run recorder, and a save is held to the workspace's quota, file
count and file cap, with a message that says what is over and how to free room."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from textual.pilot import Pilot

from workbench.files.workspace import workspace_folder
from workbench.tui.app import make_app
from workbench.tui.dialogs.path import PathDialog
from workbench.tui.screens.editor import EditorScreen
from workbench.wire.settings import AppSettings

from .support import run, screen_lines
from .test_workspace_app import type_path

RECORD = '{"type": "header", "format": 1}\n'


def served(tmp_path: Path, **limits: Any):
    workspace = workspace_folder(tmp_path / "data", "ann")
    app = make_app(AppSettings(paused=True, workspace=workspace, **limits))
    return app, app.station.files.workspace


async def open_editor(pilot: Pilot) -> EditorScreen:
    await pilot.press("e")
    editor = pilot.app.screen
    assert isinstance(editor, EditorScreen)
    await pilot.press("space")  # a change, so there is something to save
    return editor


def test_the_editor_will_not_overwrite_a_run_record(tmp_path):
    app, workspace = served(tmp_path)
    record = workspace / "runs" / "20250101-1" / "run-001.jsonl"
    record.parent.mkdir(parents=True)
    record.write_text(RECORD)

    async def body(pilot: Pilot) -> None:
        editor = await open_editor(pilot)
        await pilot.press("ctrl+s")
        for typed in ("~/runs/20250101-1/run-001.jsonl", "runs/20250101-1/mine.txt"):
            await type_path(pilot, typed)
            assert isinstance(app.screen, PathDialog), typed
            assert "where the workbench keeps your run records" in editor.status
            assert "never changed" in editor.status
        await type_path(pilot, "run-001.txt")
        assert app.screen is editor and not editor.dirty

    run(app, body)
    assert record.read_text() == RECORD
    assert sorted(p.name for p in record.parent.iterdir()) == ["run-001.jsonl"]


def test_editor_saves_stop_at_the_workspace_file_count(tmp_path):
    app, workspace = served(tmp_path, workspace_files=3)
    for name in ("a.txt", "b.txt"):
        (workspace / name).write_text("mine\n")

    async def body(pilot: Pilot) -> None:
        editor = await open_editor(pilot)
        await pilot.press("ctrl+s")
        await type_path(pilot, "c.txt")  # the third file: room for it
        assert app.screen is editor and not editor.dirty
        await pilot.press("space", "a")  # save as: a fourth file
        assert isinstance(app.screen, PathDialog)
        await type_path(pilot, "d.txt")
        assert isinstance(app.screen, PathDialog)
        assert "you may keep at most 3 files and folders on this server" in editor.status
        assert "save over one of your files instead" in editor.status
        await type_path(pilot, "a.txt")  # saving over one of them is fine
        assert app.screen is editor and not editor.dirty
        assert any("saved to ~/a.txt" in line for line in screen_lines(app))

    run(app, body)
    assert sorted(p.name for p in workspace.iterdir() if p.is_file()) == [
        "a.txt",
        "b.txt",
        "c.txt",
    ]


def test_editor_saves_stop_at_the_workspace_quota(tmp_path):
    app, workspace = served(tmp_path, workspace_quota=2_000)
    (workspace / "big.bin").write_bytes(b"x" * 1_900)  # uploaded: 1.9 kB of a 2 kB quota

    async def body(pilot: Pilot) -> None:
        editor = await open_editor(pilot)
        await pilot.press("ctrl+s")
        await type_path(pilot, "maze.txt")
        assert isinstance(app.screen, PathDialog)
        status = editor.status
        assert "~/maze.txt: your files may take at most 2 kB on this server" in status
        assert "take 1.9 kB already" in status and "remove files you no longer need" in status
        (workspace / "big.bin").unlink()  # the student frees room (sftp, rm big.bin)
        await type_path(pilot, "maze.txt")
        assert app.screen is editor and not editor.dirty

    run(app, body)
    assert (workspace / "maze.txt").is_file()
