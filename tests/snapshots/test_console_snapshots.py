"""SVG snapshots of the instructor's console at 80x24: the class with the sign-off queue, and
one request opened. The store is filled with fixed times, so the pictures are the same on every
run."""

from __future__ import annotations

from datetime import UTC, datetime

from textual.pilot import Pilot
from textual.widgets import Input

from tests.app.console_support import (
    EXERCISE,
    LAB,
    WALL_MAIN,
    WEB_LAB,
    save_progress,
    save_student,
    wall_main,
)
from tests.waiting import until
from workbench.labs.model import load_labs
from workbench.labs.signoff.instructors import KdfParams, create_instructor
from workbench.labs.store.store import Store
from workbench.tui.console_app import ConsoleApp
from workbench.tui.screens.console import ConsoleScreen

FAST = KdfParams(n=2**10, r=8, p=1)  # cheap scrypt for tests only
SIZE = (80, 24)
T0 = datetime(2026, 3, 2, 14, 5, 9, tzinfo=UTC)


def console(data) -> ConsoleApp:
    create_instructor(data, "Dr Chen", "correct horse battery", kdf=FAST)
    with Store.open(data) as store:
        for name, passed in (("ana", True), ("ben", False), ("cat", True), ("dan", False)):
            save_student(store, name, passed=passed)
        store.queue.request("cat", "eve", "eve", LAB, EXERCISE, now=T0)
        store.queue.request("ana", "", "ana", LAB, EXERCISE, now=T0.replace(minute=7))
    return ConsoleApp(Store.open(data), load_labs())


async def class_shown(pilot: Pilot) -> None:
    screen = pilot.app.screen
    assert isinstance(screen, ConsoleScreen)
    await until(lambda: screen.view is not None, "the class")
    await pilot.pause()


def test_console_with_the_class_and_the_queue(snap_compare, tmp_path):
    assert snap_compare(console(tmp_path / "data"), terminal_size=SIZE, run_before=class_shown)


def test_console_request_opened(snap_compare, tmp_path):
    async def before(pilot: Pilot) -> None:
        await class_shown(pilot)
        await pilot.press("enter")
        screen = pilot.app.screen
        await until(lambda: getattr(screen, "request", None) is not None, "the request")
        for field in screen.query(Input):
            field.cursor_blink = False
        await pilot.pause()

    assert snap_compare(console(tmp_path / "data"), terminal_size=SIZE, run_before=before)


def test_console_grid_of_students_by_exercises(snap_compare, tmp_path):
    async def before(pilot: Pilot) -> None:
        await class_shown(pilot)
        await pilot.press("g")
        await pilot.pause()

    assert snap_compare(console(tmp_path / "data"), terminal_size=SIZE, run_before=before)


def test_console_request_with_a_programs_evidence(snap_compare, tmp_path):
    """The evidence of a program's runs in words: program and digest, sensors, measures in
    blocks and pixels, tries per question; the marks for mixed and shared programs."""
    data = tmp_path / "data"
    create_instructor(data, "Dr Chen", "correct horse battery", kdf=FAST)
    with Store.open(data) as store:
        mixed = wall_main("ana", sensors_program=("other.viple", "cd" * 32))
        save_progress(store, "ana", mixed)
        save_progress(store, "ben", wall_main("ben", attempt="att-2"))
        store.queue.request("ana", "", "ana", WEB_LAB, WALL_MAIN, now=T0)

    async def before(pilot: Pilot) -> None:
        await class_shown(pilot)
        await pilot.press("enter")
        screen = pilot.app.screen
        await until(lambda: getattr(screen, "request", None) is not None, "the request")
        for field in screen.query(Input):
            field.cursor_blink = False
        await pilot.pause()

    app = ConsoleApp(Store.open(data), load_labs())
    assert snap_compare(app, terminal_size=SIZE, run_before=before)
