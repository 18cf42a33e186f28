"""The instructor's console: the class live from the store, the sign-off queue, and signing off
or declining a request from the instructor's own app."""

from __future__ import annotations

from textual.widgets import OptionList, Static

from workbench.labs.instructors import KdfParams, create_instructor
from workbench.labs.model import load_labs
from workbench.labs.queue import DECLINED, SIGNED
from workbench.labs.store import Store
from workbench.labs.verify import verify_log
from workbench.tui.console_app import ConsoleApp
from workbench.tui.dialogs.pair import PairDialog
from workbench.tui.screens.console import ConsoleScreen
from workbench.tui.screens.console_request import RequestScreen
from workbench.tui.screens.replay import ReplayScreen

from .console_support import EXERCISE, LAB, save_student, until, write_record
from .support import screen_lines, sync

FAST = KdfParams(n=2**10, r=8, p=1)  # cheap scrypt for tests only
PASS = "correct horse battery"


def console(data) -> ConsoleApp:
    return ConsoleApp(Store.open(data), load_labs())


def queue_lines(app: ConsoleApp) -> list[str]:
    listing = app.screen.query_one("#console-queue", OptionList)
    return [str(o.prompt) for o in listing.options]


def class_lines(app: ConsoleApp) -> list[str]:
    listing = app.screen.query_one("#console-class", OptionList)
    return [str(o.prompt) for o in listing.options]


@sync
async def test_the_class_and_the_queue_follow_the_store(tmp_path):
    data = tmp_path / "data"
    with Store.open(data) as store:
        save_student(store, "ana")
        save_student(store, "cat", passed=False)
    app = console(data)
    async with app.run_test(size=(80, 24)) as pilot:
        await until(pilot, lambda: len(class_lines(app)) == 2, "the class")
        ana, cat = class_lines(app)
        # one mark per objective: X passed, . not yet (ASCII)
        assert ana.startswith("ana") and f"{LAB}/{EXERCISE}" in ana and "X" * 3 in ana
        assert cat.startswith("cat") and "X" * 2 + "." in cat
        assert queue_lines(app) == []
        assert "nobody has asked" in str(app.screen.query_one("#console-queue-title").render())
        # a student on another app asks: the console shows it without a key pressed
        with Store.open(data) as student_side:
            student_side.request_signoff("cat", "dan", "dan", LAB, EXERCISE)
        await until(pilot, lambda: len(queue_lines(app)) == 1, "the request")
        assert queue_lines(app)[0].startswith("1. cat and dan")
        await until(pilot, lambda: "waiting #1" in class_lines(app)[1], "cat's place")
        assert any("Sign-off queue: 1 waiting" in line for line in screen_lines(app))


@sync
async def test_the_instructor_signs_a_request_with_their_own_passphrase(tmp_path):
    data = tmp_path / "data"
    create_instructor(data, "Dr Chen", PASS, kdf=FAST)
    record = write_record(tmp_path / "run-003.jsonl")
    with Store.open(data) as store:
        save_student(store, "ana", record=str(record))
        store.set_place("ben", LAB, EXERCISE)  # ben is a student of the class
        store.request_signoff("ana", "ben", "ben", LAB, EXERCISE)
    app = console(data)
    async with app.run_test(size=(80, 24)) as pilot:
        await until(pilot, lambda: len(queue_lines(app)) == 1, "the request")
        await pilot.press("enter")
        request = app.screen
        assert isinstance(request, RequestScreen)
        await until(pilot, lambda: request.request is not None, "the saved progress")
        shown = "\n".join(screen_lines(app))
        assert "ana and ben ask for sign-off" in shown and "driver ben" in shown
        assert "evidence: run 3 by keys (ben)" in shown and "all objectives pass" in shown
        assert "time to the exit 41.50 s" in shown
        # the evidence run replays in the maze view
        request.action_replay()
        await until(pilot, lambda: isinstance(app.screen, ReplayScreen), "the replay")
        await pilot.press("escape")
        await until(pilot, lambda: app.screen is request, "back from the replay")
        # a wrong passphrase is refused and counted
        await pilot.click("#request-passphrase")
        await pilot.press(*"not the one!", "enter")
        # the pair is the instructor's to confirm: ben worked on it and agrees
        await until(pilot, lambda: isinstance(app.screen, PairDialog), "the pair's question")
        await pilot.press("y")
        await until(pilot, lambda: "wrong passphrase" in status(request), "the refusal")
        with Store.open(data) as store:
            assert store.lockout("Dr Chen").failures == 1
        await pilot.press(*PASS, "enter")
        await until(pilot, lambda: "signed off ana and ben" in status(request), "the sign-off")
        await pilot.press("escape")
        await until(pilot, lambda: isinstance(app.screen, ConsoleScreen), "the console")
        await until(pilot, lambda: queue_lines(app) == [], "the queue emptied")
    with Store.open(data) as store:
        (row,) = store.signoffs()
        state = store.queue_state("ana", LAB, EXERCISE)
        log = verify_log(store.signoffs(), {"Dr Chen": _public(data)})
    assert (row.student, row.partner, row.driver, row.instructor) == (
        "ana",
        "ben",
        "ben",
        "Dr Chen",
    )
    assert row.run_record == str(record) and state.entry.state == SIGNED
    assert log.ok


def _public(data):
    from workbench.labs.roster import load_roster, roster_path

    return load_roster(roster_path(data))["Dr Chen"]


def status(screen) -> str:
    return str(screen.query_one("#request-status", Static).render())


@sync
async def test_a_decline_needs_a_note_and_the_student_reads_it(tmp_path):
    data = tmp_path / "data"
    create_instructor(data, "Dr Chen", PASS, kdf=FAST)
    with Store.open(data) as store:
        save_student(store, "cat", passed=False)
        store.request_signoff("cat", "", "cat", LAB, EXERCISE)
    app = console(data)
    async with app.run_test(size=(80, 24)) as pilot:
        await until(pilot, lambda: len(queue_lines(app)) == 1, "the request")
        await pilot.press("enter")
        request = app.screen
        await until(pilot, lambda: request.request is not None, "the saved progress")
        assert "2 of 3 objectives pass" in "\n".join(screen_lines(app))
        await pilot.press("ctrl+d")
        assert "write a note first" in status(request)
        await pilot.press(*"answer the last question", "ctrl+d")
        await until(pilot, lambda: isinstance(app.screen, ConsoleScreen), "the console")
        await until(pilot, lambda: queue_lines(app) == [], "the queue emptied")
        assert "declined cat" in str(app.screen.query_one("#console-message").render())
    with Store.open(data) as store:
        entry = store.queue_state("cat", LAB, EXERCISE).entry
        assert store.signoffs() == []
    assert entry.state == DECLINED and entry.note == "answer the last question"
    assert entry.instructor == "Dr Chen"


@sync
async def test_signing_work_that_does_not_pass_needs_the_override_and_a_note(tmp_path):
    data = tmp_path / "data"
    create_instructor(data, "Dr Chen", PASS, kdf=FAST)
    with Store.open(data) as store:
        save_student(store, "cat", passed=False)
        store.request_signoff("cat", "", "cat", LAB, EXERCISE)
    app = console(data)
    async with app.run_test(size=(80, 24)) as pilot:
        await until(pilot, lambda: len(queue_lines(app)) == 1, "the request")
        await pilot.press("enter")
        request = app.screen
        await until(pilot, lambda: request.request is not None, "the saved progress")
        await pilot.press(*PASS, "enter")
        await until(pilot, lambda: "override" in status(request), "the refusal")
    with Store.open(data) as store:
        assert store.signoffs() == [] and len(store.signoff_queue()) == 1
