"""What the labs read from the store as they open (``read_work``): the saved progress and
the place, or why they could not be read, never an exception."""

from __future__ import annotations

import pytest

from workbench.labs.checks import ExerciseProgress
from workbench.labs.progress import LabProgress, read_work
from workbench.labs.store.store import Store, StoreUnavailable

DRIVE = ("unity-simulator", "drive-by-wire")


@pytest.fixture
def store(tmp_path):
    with Store.open(tmp_path / "data") as opened:
        yield opened


def save_answer(store: Store, answer: str) -> None:
    progress = ExerciseProgress(*DRIVE, objectives=[], answers={"tcp-port": answer})
    store.progress.save("ana", *DRIVE, progress.as_dict())
    store.progress.set_place("ana", *DRIVE)


def test_the_saved_progress_and_the_place_are_read_and_taken(store):
    save_answer(store, "1350")
    work = read_work(store, "ana", "ben")
    assert not work.away and not work.error
    assert work.place == DRIVE
    lab_progress = LabProgress("ana", "ben", reading=True)
    lab_progress.take_work(work)
    assert not lab_progress.reading
    assert lab_progress.answers[DRIVE] == {"tcp-port": "1350"}


def test_a_database_that_does_not_answer_in_time_reads_as_away(store, monkeypatch):
    save_answer(store, "1350")

    def given_up(*args, **kw):
        raise StoreUnavailable("course: the database did not answer within 5 s")

    monkeypatch.setattr(store.progress, "of", given_up)
    work = read_work(store, "ana")
    assert work.away and work.saved is None and work.place is None
    lab_progress = LabProgress("ana", reading=True)
    lab_progress.take_work(work)  # the student goes on with nothing read
    assert not lab_progress.reading and not lab_progress.answers


def test_a_damaged_row_is_said_and_a_place_that_cannot_be_read_is_left_out(store, monkeypatch):
    with store.write() as tx:
        tx.execute(
            "INSERT INTO progress (student, lab, exercise, progress, updated_at) "
            "VALUES (?, ?, ?, ?, ?)",
            ("ana", *DRIVE, "{not json", "2026-03-02T10:00:00Z"),
        )
    work = read_work(store, "ana")
    assert not work.away and "is not JSON" in work.error and work.saved is None

    def unreadable(*args, **kw):
        raise StoreUnavailable("course: the database went away")

    monkeypatch.setattr(store.progress, "of", lambda student, lab=None: {})
    monkeypatch.setattr(store.progress, "place", unreadable)
    work = read_work(store, "ana")
    assert work.saved is not None and work.place is None and not work.away
