"""A served student's app on a course database: a run record closed by the end of its run and
a maze saved in the editor reach the database as soon as they are on disk; a database that
hangs holds up neither the save nor the keys, and the file goes once it answers."""

from __future__ import annotations

import threading
from pathlib import Path

from textual.pilot import Pilot

from tests.waiting import until
from workbench.files.workspace import workspace_folder
from workbench.labs.store.store import Store
from workbench.tui.app import make_app
from workbench.tui.screens.editor import EditorScreen
from workbench.wire.settings import AppSettings

from .support import run, said
from .test_workspace_app import type_path


def stored(data: Path, db: str, path: str) -> bytes | None:
    with Store.open(data, db=db) as store:
        got = store.workspaces.file("ann", path)
    return got[1] if got is not None else None


def test_a_saved_maze_and_a_closed_run_record_reach_the_course_database(tmp_path, pg_url):
    data = tmp_path / "server-one"
    workspace = workspace_folder(data, "ann")
    app = make_app(
        AppSettings(
            noise="off", student="ann", student_fixed=True, data_dir=data, db=pg_url,
            workspace=workspace, record_dir=workspace / "runs" / "20260302-140509",
        )
    )  # fmt: skip

    async def body(pilot: Pilot) -> None:
        station = app.station
        await pilot.press("a")  # the robot spins: a run, recorded
        await until(lambda: station.snapshot().time > 0.5, "the run going")
        await pilot.press("r")
        await until(lambda: len(station.runs) == 1, "the run ending")
        record = Path(station.runs[0].record)
        rel = record.relative_to(app.station.files.workspace).as_posix()
        await until(
            lambda: stored(data, pg_url, rel) == record.read_bytes(),
            "the run record in the course database",
            every=0.2,
        )
        await pilot.press("e")
        editor = app.screen
        assert isinstance(editor, EditorScreen)
        await pilot.press("space", "ctrl+s")
        await type_path(pilot, "mine.txt")
        assert editor.status == "saved to ~/mine.txt"
        saved = (app.station.files.workspace / "mine.txt").read_bytes()
        await until(
            lambda: stored(data, pg_url, "mine.txt") == saved,
            "the maze in the course database",
            every=0.2,
        )
        assert "course store" not in said(app)  # nothing to tell while sends succeed

    run(app, body)


def test_a_save_while_the_course_database_hangs_returns_at_once_and_is_sent_later(
    tmp_path, pg_server, pg_url, monkeypatch
):
    monkeypatch.setenv("WORKBENCH_DB_TIMEOUT", "1")
    data = tmp_path / "server-one"
    workspace = workspace_folder(data, "ann")
    app = make_app(
        AppSettings(
            noise="off", student="ann", student_fixed=True, data_dir=data, db=pg_url,
            workspace=workspace,
        )
    )  # fmt: skip

    async def body(pilot: Pilot) -> None:
        await pilot.press("e")
        editor = app.screen
        assert isinstance(editor, EditorScreen)
        pids = pg_server.freeze()
        safety = threading.Timer(60, pg_server.thaw, (pids,))
        safety.start()
        try:
            await pilot.press("space", "ctrl+s")
            await type_path(pilot, "mine.txt")
            assert editor.status == "saved to ~/mine.txt"
            assert app.pusher is not None and app.pusher.waiting == ["mine.txt"]
            cursor = editor.editor.cursor
            await pilot.press("right", "down")  # the editor still takes keys
            await until(lambda: editor.editor.cursor != cursor, "the cursor moving")
        finally:
            safety.cancel()
            pg_server.thaw(pids)
        saved = (app.station.files.workspace / "mine.txt").read_bytes()
        await until(
            lambda: stored(data, pg_url, "mine.txt") == saved,
            "the maze in the course database once it answers",
            timeout=60,
            every=0.2,
        )

    run(app, body)
