"""The labs on a course's PostgreSQL database: a student resumes on another lab server, and
keeps working while the database restarts."""

from __future__ import annotations

import asyncio
import threading
import time

import pytest
from textual.pilot import Pilot
from textual.widgets import Checkbox, Input

from workbench.labs.instructors import KdfParams, create_instructor
from workbench.labs.pending import pending_path
from workbench.labs.store import Store
from workbench.tui.dialogs.signoff import SignoffModal
from workbench.tui.screens.labs import LOADING, UNREACHABLE, LabsScreen
from workbench.tui.screens.main import MainScreen

from .labs_support import DRIVE, lab_app, open_exercise, signing_over, text
from .support import run, said

FAST = KdfParams(n=2**10, r=8, p=1)  # cheap scrypt for tests only
PASS = "correct horse battery"


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


def test_changes_kept_while_the_database_is_down_outlive_the_app_and_are_saved_by_the_next(
    tmp_path, pg_server, pg_url
):
    data = tmp_path / "data"
    first = lab_app(data, db=pg_url)
    kept = pending_path(data, "ana")

    async def work_offline(pilot: Pilot) -> None:
        screen = await open_exercise(pilot, DRIVE)
        pg_server.stop()
        screen.query_one("#q-tcp-port", Input).value = "4242"
        await pilot.pause()
        assert "saved as soon as it is back" in text(screen, "#labs-message")
        assert kept.is_file()  # kept in the data folder at once, not only at the end
        await pilot.press("ctrl+q")

    try:
        run(first, work_offline)
        assert kept.is_file()  # the student quit with the database still down
    finally:
        pg_server.start()
    second = lab_app(data, db=pg_url)  # the next start, the database back

    async def resume(pilot: Pilot) -> None:
        deadline = time.monotonic() + 15
        while kept.is_file() and time.monotonic() < deadline:
            await asyncio.sleep(0.2)
        await pilot.pause()
        assert said(second).startswith("saving resumed")
        assert "saving resumed" in str(second.screen.query_one("#message").render())

    run(second, resume)
    assert not kept.is_file()
    with Store.open(tmp_path / "elsewhere", db=pg_url) as store:
        saved = store.progress("ana")[("unity-simulator", "drive-by-wire")]
    assert saved["answers"] == {"tcp-port": "4242"}


def test_retries_run_beside_the_app_one_at_a_time(tmp_path, pg_server, pg_url, monkeypatch):
    monkeypatch.setattr("workbench.tui.screens.labs.RETRY_SECONDS", 0.1)
    app = lab_app(tmp_path / "data", db=pg_url)
    running, most = 0, 0

    async def body(pilot: Pilot) -> None:
        nonlocal running, most
        screen = await open_exercise(pilot, DRIVE)
        store = app.store
        flush = store.flush
        back = threading.Event()

        def slow_flush() -> bool:
            """A database that does not answer: a try off the app's thread (the screen's
            retries) waits until the server is back; the app's own save finds it refusing."""
            nonlocal running, most
            running += 1
            most = max(most, running)
            if threading.current_thread() is not threading.main_thread():
                back.wait(30)
            running -= 1
            return flush()

        monkeypatch.setattr(store, "flush", slow_flush)
        pg_server.stop()
        try:
            screen.query_one("#q-tcp-port", Input).value = "77"
            await pilot.pause()
            for _ in range(1000):
                if running:
                    break
                await asyncio.sleep(0.01)
            assert running == 1  # a retry is under way now, waiting for the database
            frames = app.frames
            assert isinstance(app.screen, LabsScreen) and app.station.paused
            await pilot.press("escape", "p")  # back on the main screen, running
            await pilot.pause(0.5)
            # the keys were not held up by the try: they took effect while it still waits
            assert isinstance(app.screen, MainScreen) and not app.station.paused
            assert running == 1
            assert app.frames > frames  # and the screen kept being drawn
        finally:
            pg_server.start()
            back.set()
        deadline = time.monotonic() + 15
        while store.pending and time.monotonic() < deadline:
            await asyncio.sleep(0.2)
        assert not store.pending

    run(app, body)
    assert most == 1


class Hang:
    """A course database that stops answering, in one of two ways, and its release: the whole
    server stopped (SIGSTOP) or the progress table locked by another connection. It is let go
    at the latest after ``limit`` seconds, so that an app frozen by it cannot hang the tests."""

    def __init__(self, how: str, server, url: str, limit: float = 40.0):
        self.how, self.server, self.url = how, server, url
        self._pids: list[int] = []
        self._locker = None
        self._released = threading.Lock()
        self._timer = threading.Timer(limit, self.release)

    def start(self) -> None:
        if self.how == "stopped":
            self._pids = self.server.freeze()
        else:
            import psycopg

            self._locker = psycopg.connect(self.url)
            self._locker.execute("LOCK TABLE progress IN ACCESS EXCLUSIVE MODE")
        self._timer.start()

    def release(self) -> None:
        with self._released:
            self._timer.cancel()
            if self._pids:
                self.server.thaw(self._pids)
                self._pids = []
            if self._locker is not None:
                self._locker.rollback()
                self._locker.close()
                self._locker = None


@pytest.mark.parametrize("how", ["stopped", "locked"])
def test_a_database_that_hangs_never_freezes_the_app_and_the_work_waits_for_it(
    tmp_path, pg_server, pg_url, monkeypatch, how
):
    monkeypatch.setenv("WORKBENCH_DB_TIMEOUT", "2")  # given up after 2 s (stopped: 2 s more)
    app = lab_app(tmp_path / "data", db=pg_url)
    hang = Hang(how, pg_server, pg_url)

    async def body(pilot: Pilot) -> None:
        screen = await open_exercise(pilot, DRIVE)
        store = app.store
        hang.start()
        try:
            screen.query_one("#q-tcp-port", Input).value = "1350"  # saving the answer begins
            await pilot.pause()
            # while the save waits for the database, keys are handled and the screen drawn
            await pilot.press("escape", "p")
            assert isinstance(app.screen, MainScreen) and not app.station.paused
            frames = app.frames
            await pilot.press("w")
            while app.frames == frames:
                await asyncio.sleep(0.01)
            assert store.pending  # the answer is still on its way
            await pilot.press("p", "l")
            assert app.screen is screen
            message = ""
            deadline = time.monotonic() + 15  # the database is given up on within seconds
            while "saved as soon as it is back" not in message and time.monotonic() < deadline:
                await asyncio.sleep(0.05)
                message = text(screen, "#labs-message")
            assert message.startswith("the course database cannot be reached: your progress")
            assert "kept here" in message and "saved as soon as it is back" in message
            assert store.pending
        finally:
            hang.release()
        back = "the course database is back: your progress is saved"
        deadline = time.monotonic() + 20
        while text(screen, "#labs-message") != back and time.monotonic() < deadline:
            await asyncio.sleep(0.1)
        assert text(screen, "#labs-message") == back
        assert not store.pending

    run(app, body)
    with Store.open(tmp_path / "elsewhere", db=pg_url) as store:
        saved = store.progress("ana")[("unity-simulator", "drive-by-wire")]
    assert saved["answers"] == {"tcp-port": "1350"}


def test_the_labs_open_at_once_on_a_database_that_hangs_and_fill_in_once_it_answers(
    tmp_path, pg_server, pg_url, monkeypatch
):
    """The course database stopped (SIGSTOP) when the student opens the labs: the screen is
    there at once, saying it loads their progress, and keys work meanwhile; then it says the
    database is away, and once it answers the saved progress is shown where they left off."""
    first = lab_app(tmp_path / "server-one", db=pg_url)

    async def answer(pilot: Pilot) -> None:
        screen = await open_exercise(pilot, DRIVE)
        screen.query_one("#q-tcp-port", Input).value = "1350"
        await pilot.pause()

    run(first, answer)
    monkeypatch.setenv("WORKBENCH_DB_TIMEOUT", "2")
    app = lab_app(tmp_path / "server-two", db=pg_url)
    hang = Hang("stopped", pg_server, pg_url)

    async def body(pilot: Pilot) -> None:
        hang.start()
        try:
            await pilot.press("l")
            screen = app.screen
            assert isinstance(screen, LabsScreen)  # open while the database says nothing
            assert text(screen, "#labs-message") == LOADING
            assert not screen.loaded.is_set()
            await pilot.press("escape", "p")  # keys are handled while the progress is read
            assert isinstance(app.screen, MainScreen) and not app.station.paused
            await pilot.press("p", "l")
            assert app.screen is screen
            await asyncio.wait_for(screen.loaded.wait(), 40)
            await pilot.pause()
            assert text(screen, "#labs-message").startswith(
                f"{UNREACHABLE}: saved progress is not shown yet"
            )
        finally:
            hang.release()
        back = "the course database is back: your progress is saved"
        deadline = time.monotonic() + 20
        while text(screen, "#labs-message") != back and time.monotonic() < deadline:
            await asyncio.sleep(0.1)
        await pilot.pause()
        assert text(screen, "#labs-message") == back
        assert text(screen, "#labs-title") == "Unity simulator: Drive by wire"  # where they were
        assert screen.query_one("#q-tcp-port", Input).value == "1350"

    run(app, body)


def statement_waits_for_a_lock(url: str) -> bool:
    import psycopg

    with psycopg.connect(url, autocommit=True) as conn:
        row = conn.execute(
            "SELECT count(*) FROM pg_stat_activity WHERE wait_event_type = 'Lock'"
        ).fetchone()
    return bool(row and row[0])


def test_signing_off_behind_a_save_stuck_on_the_database_keeps_the_app_answering(
    tmp_path, pg_server, pg_url, monkeypatch
):
    """A save of progress stuck on a locked table holds the store; a sign-off started then
    waits for it in a thread: the dialog takes keys meanwhile, and signs once it is free."""
    monkeypatch.setenv("WORKBENCH_DB_TIMEOUT", "20")
    data = tmp_path / "data"
    with Store.open(data, db=pg_url) as store:
        create_instructor(data, "Dr Chen", PASS, kdf=FAST, store=store)
    app = lab_app(data, db=pg_url)
    hang = Hang("locked", pg_server, pg_url)

    async def body(pilot: Pilot) -> None:
        await open_exercise(pilot, DRIVE)
        await pilot.press("i")
        modal = app.screen
        assert isinstance(modal, SignoffModal)
        await asyncio.wait_for(modal.roster_read.wait(), 20)  # read in a thread
        await pilot.pause()
        modal.query_one("#signoff-passphrase", Input).value = PASS
        modal.query_one("#signoff-override", Checkbox).value = True
        note = modal.query_one("#signoff-note", Input)
        note.value = "checked at the station"
        store = app.store
        saved = store.progress("ana")[("unity-simulator", "drive-by-wire")]
        hang.start()
        try:
            # the labs screen's save of the exercise, on its way in the store's thread
            store.save_progress("ana", "unity-simulator", "drive-by-wire", saved)
            for _ in range(200):
                if await asyncio.to_thread(statement_waits_for_a_lock, pg_url):
                    break
                await asyncio.sleep(0.05)
            note.focus()
            await pilot.press("enter")  # sign: the store is held by the stuck save
            await pilot.press("end", "!")
            await pilot.pause()
            assert modal.signing is not None and not modal.signed  # still waiting ...
            assert note.value == "checked at the station!"  # ... and the key was taken
        finally:
            hang.release()
        await signing_over(pilot, modal)
        assert "Signed off by Dr Chen (override)." in text(modal, "#signoff-done")

    run(app, body)
