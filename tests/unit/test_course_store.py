"""The course store's life beside a front end, without one: what it publishes as it opens."""

from __future__ import annotations

import queue

from workbench.labs.course_store import CourseStore, Opened, StoreEvent
from workbench.labs.store.store import Store


def opened(course: CourseStore, student: str, partner: str = "", **kw) -> Opened:
    """Open ``course`` for the pair and wait for the news that it is open (from its thread)."""
    news: queue.Queue[StoreEvent] = queue.Queue()
    course.subscribe(news.put)
    course.open_for(student, partner, **kw)
    event = news.get(timeout=30)
    assert isinstance(event, Opened)
    return event


def test_the_pair_is_spelled_as_the_store_holds_them_unless_the_name_is_a_login(tmp_path):
    with Store.open(tmp_path) as store:
        store.progress.set_place("Alice Doe", "lab", "one")
    course = CourseStore(tmp_path, None, "alice  doe")
    event = opened(course, "alice  doe", "ben")
    assert (event.student, event.partner, event.problem) == ("Alice Doe", "ben", "")
    assert event.store is course.store is not None
    course.finish(1.0)
    served = CourseStore(tmp_path, None, "alice  doe")
    assert opened(served, "alice  doe", respell=False).student == "alice  doe"
    served.finish(1.0)


def test_a_data_folder_that_cannot_be_opened_says_why_and_saves_nothing(tmp_path):
    blocker = tmp_path / "file"
    blocker.write_text("not a folder")
    event = opened(CourseStore(blocker, None, "ana"), "ana")
    assert event.store is None
    assert event.problem.startswith("cannot open the data folder, so nothing is saved: ")
    assert str(blocker) in event.problem
