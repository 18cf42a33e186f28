"""The sign-off queue in the store, the same on SQLite and on PostgreSQL (a real server the test
session starts): students ask, wait in order, and an instructor signs or declines with a note."""

from __future__ import annotations

from datetime import UTC, datetime, timedelta

import pytest

from workbench.labs.store.queue import DECLINED, SIGNED, WAITING, WITHDRAWN
from workbench.labs.store.store import Store, StoreError

T0 = datetime(2026, 3, 2, 14, 5, 9, tzinfo=UTC)


def at(seconds: float) -> datetime:
    return T0 + timedelta(seconds=seconds)


def test_requests_wait_in_the_order_asked_and_each_sees_its_place(store):
    store.queue.request("ana", "ben", "ben", "unity", "ex1", now=at(0))
    store.queue.request("cat", "", "cat", "unity", "ex2", now=at(1))
    third = store.queue.request("dan", "", "dan", "web", "ex1", now=at(2))
    assert third.place == 3 and third.waiting == 3 and third.entry.state == WAITING
    assert [(e.student, e.exercise) for e in store.queue.waiting()] == [
        ("ana", "ex1"),
        ("cat", "ex2"),
        ("dan", "ex1"),
    ]
    first = store.queue.waiting()[0]
    assert first.pair == "ana and ben" and first.driver == "ben"
    # asking again while waiting keeps the place
    again = store.queue.request("ana", "ben", "ana", "unity", "ex1", now=at(9))
    assert again.place == 1 and again.entry.driver == "ana"
    # an exercise nobody asked about has no place
    assert store.queue.state("ana", "unity", "ex9").entry is None


def test_a_signed_request_leaves_the_queue_and_those_behind_move_up(store):
    store.queue.request("ana", "", "ana", "unity", "ex1", now=at(0))
    store.queue.request("cat", "", "cat", "unity", "ex1", now=at(1))
    entry = store.queue.waiting()[0]
    done = store.queue.mark_signed(entry.id, "Dr Chen", now=at(5))
    assert done.state == SIGNED and done.instructor == "Dr Chen"
    assert store.queue.state("cat", "unity", "ex1").place == 1
    assert store.queue.state("ana", "unity", "ex1").place is None
    with pytest.raises(StoreError, match="already signed by Dr Chen"):
        store.queue.decline(entry.id, "Dr Lee", "too late")


def test_a_decline_carries_a_note_and_asking_again_goes_to_the_back(store):
    store.queue.request("ana", "", "ana", "unity", "ex1", now=at(0))
    store.queue.request("cat", "", "cat", "unity", "ex1", now=at(1))
    entry = store.queue.waiting()[0]
    with pytest.raises(StoreError, match="needs a note"):
        store.queue.decline(entry.id, "Dr Chen", "   ")
    declined = store.queue.decline(entry.id, "Dr Chen", "run it again from the start", at(3))
    seen = store.queue.state("ana", "unity", "ex1")
    assert seen.entry.state == DECLINED and seen.entry.note == "run it again from the start"
    assert seen.entry.instructor == "Dr Chen" and seen.place is None
    assert declined.decided_at.startswith("2026-03-02T14:05:12")
    back = store.queue.request("ana", "", "ana", "unity", "ex1", now=at(4))
    assert back.place == 2 and back.entry.note == "" and back.entry.instructor == ""


def test_a_withdrawn_request_stops_waiting(store):
    store.queue.request("ana", "", "ana", "unity", "ex1", now=at(0))
    assert store.queue.withdraw("ana", "unity", "ex1", now=at(1))
    assert not store.queue.withdraw("ana", "unity", "ex1", now=at(2))
    assert store.queue.state("ana", "unity", "ex1").entry.state == WITHDRAWN
    assert store.queue.waiting() == []
    entry = store.queue.state("ana", "unity", "ex1").entry
    with pytest.raises(StoreError, match="already withdrawn"):
        store.queue.mark_signed(entry.id, "Dr Chen")


def test_hostile_ids_and_notes_are_refused_with_the_reason(store):
    with pytest.raises(StoreError, match="lab id"):
        store.queue.request("ana", "", "ana", "x" * 500, "ex1")
    with pytest.raises(StoreError, match="exercise id"):
        store.queue.request("ana", "", "ana", "unity", "ex\x1b[2J")
    store.queue.request("ana", "", "ana", "unity", "ex1")
    entry = store.queue.waiting()[0]
    with pytest.raises(StoreError, match="keep it to 500"):
        store.queue.decline(entry.id, "Dr Chen", "n" * 501)
    with pytest.raises(StoreError, match="not in the sign-off queue"):
        store.queue.mark_signed(entry.id + 1000, "Dr Chen")


def test_two_stores_on_one_database_share_the_queue(store, tmp_path):
    other = Store.open(tmp_path / "data", db=store.backend.url if store.postgres else None)
    try:
        other.queue.request("ana", "", "ana", "unity", "ex1", now=at(0))
        assert [e.student for e in store.queue.waiting()] == ["ana"]
        store.queue.decline(store.queue.waiting()[0].id, "Dr Chen", "show me the replay")
        assert other.queue.state("ana", "unity", "ex1").entry.note == "show me the replay"
    finally:
        other.close()


def test_the_places_of_every_student_are_listed(store):
    store.progress.set_place("ana", "unity", "ex2")
    store.progress.set_place("cat", "web", "ex1")
    assert store.progress.places() == {"ana": ("unity", "ex2"), "cat": ("web", "ex1")}
