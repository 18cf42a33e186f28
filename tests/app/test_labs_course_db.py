"""The labs on a course's PostgreSQL database: a student resumes on another lab server, and
keeps working while the database restarts."""

from __future__ import annotations

import threading

import pytest
from textual.pilot import Pilot
from textual.widgets import Input, OptionList

from tests.waiting import until
from workbench.labs.store.pending import pending_path
from workbench.labs.store.store import Store
from workbench.tui.screens.labs import LabsScreen
from workbench.tui.screens.main import MainScreen

from .labs_support import DRIVE, lab_app, open_exercise, open_labs, text, try_answer
from .support import run, said


def test_a_student_resumes_on_another_server_where_they_left_off(tmp_path, pg_url):
    first = lab_app(tmp_path / "server-one", db=pg_url)

    async def drive(pilot: Pilot) -> None:
        screen = await open_exercise(pilot, DRIVE)
        await pilot.press("a", "escape", "w", "a", "s", "d", "space", "l")
        await pilot.pause()
        assert text(screen, "#labs-objectives").startswith("[X] drove with w, a, s, d and space")
        try_answer(screen, "tcp-port", "1351")
        await pilot.pause()
        try_answer(screen, "tcp-port", "1350")
        await pilot.pause()

    run(first, drive)
    second = lab_app(tmp_path / "server-two", db=pg_url)  # another machine, the same database

    async def resume(pilot: Pilot) -> None:
        screen = await open_labs(pilot)
        assert "Drive by wire" in text(screen, "#labs-title")  # reopened where they were
        assert text(screen, "#labs-objectives").startswith(
            "[X] drove with w, a, s, d and space: passed earlier"
        )
        assert screen.query_one("#q-tcp-port", Input).value == "1350"
        # both tries came back from the course database, and are shown
        reason = screen.query_one("#q-tcp-port", Input).parent.query_one(".question-reason")
        assert str(reason.render()) == "[X] correct (2 tries)"

    run(second, resume)


def test_the_database_going_away_is_shown_and_the_work_is_saved_when_it_is_back(
    tmp_path, pg_server, pg_url
):
    app = lab_app(tmp_path / "data", db=pg_url)

    async def body(pilot: Pilot) -> None:
        screen = await open_exercise(pilot, DRIVE)
        pg_server.stop()
        try:
            try_answer(screen, "tcp-port", "1350")
            await pilot.pause()
            message = text(screen, "#labs-message")
            assert message.startswith("the course database cannot be reached: your progress")
            assert "saved as soon as it is back" in message
            await pilot.press("w")  # the robot still drives
            await pilot.pause()
        finally:
            pg_server.start()
        await until(lambda: not app.store.pending, "the progress saved", every=0.2)
        await pilot.pause()
        assert text(screen, "#labs-message") == (
            "the course database is back: your progress is saved"
        )

    run(app, body)
    with Store.open(tmp_path / "elsewhere", db=pg_url) as store:
        saved = store.progress.of("ana")[("unity-simulator", "drive-by-wire")]
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
        try_answer(screen, "tcp-port", "4242")
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
        await until(lambda: not kept.is_file(), "the kept changes saved", every=0.2)
        await pilot.pause()
        assert said(second).startswith("saving resumed")
        assert "saving resumed" in str(second.screen.query_one("#message").render())

    run(second, resume)
    assert not kept.is_file()
    with Store.open(tmp_path / "elsewhere", db=pg_url) as store:
        saved = store.progress.of("ana")[("unity-simulator", "drive-by-wire")]
    assert saved["answers"] == {"tcp-port": "4242"}


def test_retries_run_beside_the_app_one_at_a_time(tmp_path, pg_server, pg_url, monkeypatch):
    monkeypatch.setattr("workbench.labs.course_store.RETRY_SECONDS", 0.1)
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
            try_answer(screen, "tcp-port", "77")
            await pilot.pause()
            await until(lambda: running, "a retry under way")
            assert running == 1  # a retry is under way now, waiting for the database
            frames = app.frames
            assert isinstance(app.screen, LabsScreen) and app.station.paused
            await pilot.press("escape", "p")  # back on the main screen, running
            # the keys were not held up by the try: they took effect while it still waits
            await until(lambda: isinstance(app.screen, MainScreen) and not app.station.paused)
            await until(lambda: app.frames > frames, "a frame drawn")  # the screen kept drawing
            assert running == 1
        finally:
            pg_server.start()
            back.set()
        await until(lambda: not store.pending, "the progress saved", every=0.2)

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
            try_answer(screen, "tcp-port", "1350")  # saving the answer begins
            await pilot.pause()
            # while the save waits for the database, keys are handled and the screen drawn
            await pilot.press("escape", "p")
            assert isinstance(app.screen, MainScreen) and not app.station.paused
            frames = app.frames
            await pilot.press("w")
            await until(lambda: app.frames != frames, "a frame drawn after the key")
            assert store.pending  # the answer is still on its way
            await pilot.press("p", "l")
            assert app.screen is screen

            def kept() -> str:
                message = text(screen, "#labs-message")
                return message if "saved as soon as it is back" in message else ""

            # the database is given up on within seconds
            message = await until(kept, "the message that the work is kept")
            assert message.startswith("the course database cannot be reached: your progress")
            assert "kept here" in message and "saved as soon as it is back" in message
            assert store.pending
        finally:
            hang.release()
        back = "the course database is back: your progress is saved"
        await until(lambda: text(screen, "#labs-message") == back, "the message that it is back")
        assert not store.pending

    run(app, body)
    with Store.open(tmp_path / "elsewhere", db=pg_url) as store:
        saved = store.progress.of("ana")[("unity-simulator", "drive-by-wire")]
    assert saved["answers"] == {"tcp-port": "1350"}


@pytest.mark.parametrize("how", ["stopped", "locked"])
def test_the_labs_open_beside_a_database_that_hangs_and_the_student_goes_on(
    tmp_path, pg_server, pg_url, monkeypatch, how
):
    first = lab_app(tmp_path / "one", db=pg_url)

    async def work(pilot: Pilot) -> None:
        screen = await open_exercise(pilot, DRIVE)
        try_answer(screen, "tcp-port", "1350")
        await pilot.pause()

    run(first, work)  # saved progress the hung database holds
    # a connection or a statement is given up on after 8 s: long enough that the keys below
    # are answered while the labs still wait for the database
    monkeypatch.setenv("WORKBENCH_DB_TIMEOUT", "8")
    app = lab_app(tmp_path / "two", db=f"{pg_url}?connect_timeout=8")
    hang = Hang(how, pg_server, pg_url, limit=90)

    async def body(pilot: Pilot) -> None:
        hang.start()
        try:
            await pilot.press("l")  # the store is opened and read while the database hangs
            screen = app.screen
            assert isinstance(screen, LabsScreen)
            await pilot.pause()
            assert "loading saved work" in text(screen, "#labs-title")
            # the keys are handled and the screen drawn while the labs wait for the database
            await pilot.press("escape", "p")
            assert isinstance(app.screen, MainScreen) and not app.station.paused
            frames = app.frames
            await pilot.press("w")
            await until(lambda: app.frames != frames, "a frame drawn after the key")
            await pilot.press("p", "l")
            assert app.screen is screen
            assert screen.lab_progress.reading  # (the read still waits)

            def away() -> str:
                message = text(screen, "#labs-message")
                return message if "saved progress is not shown yet" in message else ""

            # given up on at the deadline: the labs work as with a database that is down
            message = await until(away, "the message that the database is away", timeout=60)
            assert message.startswith("the course database cannot be reached")
            assert not screen.lab_progress.reading
            listing = screen.query_one("#labs-list", OptionList)
            listing.highlighted = listing.get_option_index("unity-simulator/wall-following")
            await until(lambda: "Wall following" in text(screen, "#labs-title"), "an exercise")
        finally:
            hang.release()
        # once it is back, the saved work is read and shown
        back = "the course database is back: your progress is saved"
        await until(
            lambda: text(screen, "#labs-message") == back, "the message that it is back", 60
        )
        assert screen.lab_progress.answers[("unity-simulator", "drive-by-wire")] == {
            "tcp-port": "1350"
        }

    run(app, body)
