"""Word of a change to the store: a reader's watcher wakes at another connection's commit,
on SQLite (the file's data version) and on PostgreSQL (LISTEN/NOTIFY), and not without one."""

from __future__ import annotations

import threading
import time

import pytest

from workbench.labs.store import changes
from workbench.labs.store.changes import ChangeWaiter
from workbench.labs.store.database import StoreUnavailable
from workbench.labs.store.store import Store

LAB, EXERCISE = "web-simulator", "wall-main"


def _stores(kind: str, tmp_path, request) -> tuple[Store, Store]:
    """Two stores on one database: the reader's and a student's (another connection)."""
    if kind == "sqlite":
        data = tmp_path / "data"
        return Store.open(data), Store.open(data)
    url = request.getfixturevalue("pg_url")
    return Store.open(tmp_path / "a", db=url), Store.open(tmp_path / "b", db=url)


def _wait_for_word(watcher: changes.Changes, seconds: float = 20.0) -> bool:
    never = threading.Event()
    deadline = time.monotonic() + seconds
    while time.monotonic() < deadline:
        if watcher.wait(0.05, never):
            return True
    return False


@pytest.mark.parametrize("kind", ["sqlite", "postgresql"])
def test_a_commit_by_another_connection_is_word_and_quiet_is_none(kind, tmp_path, request):
    reader, student = _stores(kind, tmp_path, request)
    with reader, student:
        watcher = reader.watch_changes()
        try:
            never = threading.Event()
            assert not watcher.wait(0.1, never), "no write: no word"
            student.queue.request("cat", "dan", "dan", LAB, EXERCISE)
            assert _wait_for_word(watcher), "the request is word"
            assert not watcher.wait(0.1, never), "the word came once"
            # reads by anyone are no change
            student.queue.waiting()
            reader.queue.waiting()
            assert not watcher.wait(0.1, never)
            student.queue.withdraw("cat", LAB, EXERCISE)
            assert _wait_for_word(watcher), "the withdrawal is word too"
        finally:
            watcher.close()


def test_the_waiter_returns_at_once_when_woken_and_at_word_of_a_change(tmp_path):
    data = tmp_path / "data"
    with Store.open(data) as reader, Store.open(data) as student:
        wake, stop = threading.Event(), threading.Event()
        waiter = ChangeWaiter(reader.watch_changes, wake, stop, even_without_word=3600)
        try:
            wake.set()
            waiter.wait()  # returns: woken
            assert not wake.is_set(), "the wake is used up"
            done = threading.Event()

            def waiting() -> None:
                waiter.wait()
                done.set()

            thread = threading.Thread(target=waiting)
            thread.start()
            assert not done.wait(0.3), "nothing happened: still waiting"
            student.queue.request("cat", "dan", "dan", LAB, EXERCISE)
            assert done.wait(20), "the request ended the wait"
            thread.join()
        finally:
            waiter.close()


def test_a_store_that_cannot_be_watched_is_read_again_at_the_away_pace():
    made = []

    def away() -> changes.Changes:
        made.append(1)
        raise StoreUnavailable("the database cannot be reached")

    waiter = ChangeWaiter(
        away, threading.Event(), threading.Event(), away=0.05, even_without_word=3600
    )
    for _ in range(3):
        waiter.wait()  # each returns after the away pace, not the hour without word
    assert len(made) == 4, "a watcher is tried when the waiter is made, then at each wait"
