"""The labs on a course's PostgreSQL database: a student resumes on another lab server, and
keeps working while the database restarts."""

from __future__ import annotations

import asyncio
import time

from textual.pilot import Pilot
from textual.widgets import Input

from workbench.labs.store import Store

from .labs_support import DRIVE, lab_app, open_exercise, text
from .support import run


def test_a_student_resumes_on_another_server_where_they_left_off(tmp_path, pg_url):
    first = lab_app(tmp_path / "server-one", db=pg_url)

    async def drive(pilot: Pilot) -> None:
        screen = await open_exercise(pilot, DRIVE)
        await pilot.press("a", "escape", "w", "a", "s", "d", "space", "l")
        await pilot.pause()
        assert text(screen, "#labs-objectives").startswith("[X] drove with w, a, s, d and space")
        screen.query_one("#q-tcp-port", Input).value = "1350"
        await pilot.pause()

    run(first, drive)
    second = lab_app(tmp_path / "server-two", db=pg_url)  # another machine, the same database

    async def resume(pilot: Pilot) -> None:
        await pilot.press("l")
        await pilot.pause()
        screen = second.screen
        assert "Drive by wire" in text(screen, "#labs-title")  # reopened where they were
        assert text(screen, "#labs-objectives").startswith(
            "[X] drove with w, a, s, d and space: passed earlier"
        )
        assert screen.query_one("#q-tcp-port", Input).value == "1350"

    run(second, resume)


def test_the_database_going_away_is_shown_and_the_work_is_saved_when_it_is_back(
    tmp_path, pg_server, pg_url
):
    app = lab_app(tmp_path / "data", db=pg_url)

    async def body(pilot: Pilot) -> None:
        screen = await open_exercise(pilot, DRIVE)
        pg_server.stop()
        try:
            screen.query_one("#q-tcp-port", Input).value = "1350"
            await pilot.pause()
            message = text(screen, "#labs-message")
            assert message.startswith("the course database cannot be reached: your progress")
            assert "saved as soon as it is back" in message
            await pilot.press("w")  # the robot still drives
            await pilot.pause()
        finally:
            pg_server.start()
        deadline = time.monotonic() + 15
        while app.store.pending and time.monotonic() < deadline:
            await asyncio.sleep(0.2)
        await pilot.pause()
        assert text(screen, "#labs-message") == (
            "the course database is back: your progress is saved"
        )

    run(app, body)
    with Store.open(tmp_path / "elsewhere", db=pg_url) as store:
        saved = store.progress("ana")[("unity-simulator", "drive-by-wire")]
    assert saved["answers"] == {"tcp-port": "1350"}
