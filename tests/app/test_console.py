"""The instructor's console: the class live from the store, the sign-off queue, and signing off
or declining a request from the instructor's own app."""

from __future__ import annotations

import pytest
from textual.widgets import OptionList, Static

from tests.waiting import until
from workbench.labs.model import load_labs
from workbench.labs.signoff.instructors import KdfParams, create_instructor
from workbench.labs.signoff.verify import verify_log
from workbench.labs.store import changes
from workbench.labs.store.queue import DECLINED, SIGNED
from workbench.labs.store.store import Store
from workbench.tui.console_app import ConsoleApp
from workbench.tui.dialogs.pair import PairDialog
from workbench.tui.screens.console import ConsoleScreen
from workbench.tui.screens.console_request import RequestScreen
from workbench.tui.screens.replay import ReplayScreen

from .console_support import (
    EXERCISE,
    LAB,
    LONG_EXERCISE,
    WALL_MAIN,
    WEB_LAB,
    save_progress,
    save_student,
    wall_main,
    write_record,
)
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
    async with app.run_test(size=(80, 24)):
        await until(lambda: len(class_lines(app)) == 2, "the class")
        ana, cat = class_lines(app)
        # one mark per objective: X passed, . not yet (ASCII)
        assert ana.startswith("ana") and f"{LAB}/{EXERCISE}" in ana and "X" * 3 in ana
        assert cat.startswith("cat") and "X" * 2 + "." in cat
        assert queue_lines(app) == []
        assert "nobody has asked" in str(app.screen.query_one("#console-queue-title").render())
        # a student on another app asks: the console shows it without a key pressed
        with Store.open(data) as student_side:
            student_side.queue.request("cat", "dan", "dan", LAB, EXERCISE)
        await until(lambda: len(queue_lines(app)) == 1, "the request")
        assert queue_lines(app)[0].startswith("1. cat and dan")
        await until(lambda: "waiting #1" in class_lines(app)[1], "cat's place")
        assert any("Sign-off queue: 1 waiting" in line for line in screen_lines(app))


@pytest.mark.parametrize("kind", ["sqlite", "postgresql"])
def test_a_request_shows_at_word_of_the_commit_not_at_a_clock(kind, tmp_path, request, monkeypatch):
    """The console reads again when the store says another connection committed: with the
    read without word an hour away, a student's request still shows within moments."""
    monkeypatch.setattr(changes, "EVEN_WITHOUT_WORD", 3600.0)
    url = request.getfixturevalue("pg_url") if kind == "postgresql" else None
    data = tmp_path / "data"

    def opened(folder):
        return Store.open(folder, db=url) if url else Store.open(folder)

    with opened(data) as store:
        save_student(store, "cat", passed=False)

    @sync
    async def watch() -> None:
        app = ConsoleApp(opened(data), load_labs())
        async with app.run_test(size=(80, 24)):
            await until(lambda: len(class_lines(app)) == 1, "the class")
            with opened(tmp_path / "student" if url else data) as student_side:
                student_side.queue.request("cat", "dan", "dan", LAB, EXERCISE)
            await until(lambda: len(queue_lines(app)) == 1, "the request, at word of it")
            assert queue_lines(app)[0].startswith("1. cat and dan")

    watch()


@sync
async def test_the_instructor_signs_a_request_with_their_own_passphrase(tmp_path):
    data = tmp_path / "data"
    create_instructor(data, "Dr Chen", PASS, kdf=FAST)
    record = write_record(tmp_path / "run-003.jsonl")
    with Store.open(data) as store:
        save_student(store, "ana", record=str(record))
        store.progress.set_place("ben", LAB, EXERCISE)  # ben is a student of the class
        store.queue.request("ana", "ben", "ben", LAB, EXERCISE)
    app = console(data)
    async with app.run_test(size=(80, 24)) as pilot:
        await until(lambda: len(queue_lines(app)) == 1, "the request")
        await pilot.press("enter")
        request = app.screen
        assert isinstance(request, RequestScreen)
        await until(lambda: request.request is not None, "the saved progress")
        shown = "\n".join(screen_lines(app))
        assert "ana and ben ask for sign-off" in shown and "driver ben" in shown
        # evidence saved before runs kept their sensors and programs still reads whole,
        # in blocks and the unity profile's own unit (not metres)
        assert "run 3 by keys (ben) on Unity maze (unity), ended by exit" in shown
        assert "out in 41.5 s, 6.12 blocks (12.25 units), 0 collisions" in shown
        assert "on run 3, as above" in shown and "all objectives pass" in shown
        assert " m;" not in shown and "reached_exit" not in shown
        run_line = str(request.query_one("#request-run", Static).render())
        assert run_line == f"run 3 is recorded in {record}: p replays it, ctrl+g saves its picture"
        # the evidence run replays in the maze view
        request.action_replay()
        await until(lambda: isinstance(app.screen, ReplayScreen), "the replay")
        await pilot.press("escape")
        await until(lambda: app.screen is request, "back from the replay")
        # a wrong passphrase is refused and counted
        await pilot.click("#request-passphrase")
        await pilot.press(*"not the one!", "enter")
        # the pair is the instructor's to confirm: ben worked on it and agrees
        await until(lambda: isinstance(app.screen, PairDialog), "the pair's question")
        await pilot.press("y")
        await until(lambda: "wrong passphrase" in status(request), "the refusal")
        with Store.open(data) as store:
            assert store.signoffs.lockout("Dr Chen").failures == 1
        await pilot.press(*PASS, "enter")
        await until(lambda: "signed off ana and ben" in status(request), "the sign-off")
        await pilot.press("escape")
        await until(lambda: isinstance(app.screen, ConsoleScreen), "the console")
        await until(lambda: queue_lines(app) == [], "the queue emptied")
    with Store.open(data) as store:
        (row,) = store.signoffs.of()
        state = store.queue.state("ana", LAB, EXERCISE)
        log = verify_log(store.signoffs.of(), {"Dr Chen": _public(data)})
    assert (row.student, row.partner, row.driver, row.instructor) == (
        "ana",
        "ben",
        "ben",
        "Dr Chen",
    )
    assert row.run_record == str(record) and state.entry.state == SIGNED
    assert log.ok


def _public(data):
    from workbench.labs.signoff.roster import load_roster, roster_path

    return load_roster(roster_path(data))["Dr Chen"]


def status(screen) -> str:
    return str(screen.query_one("#request-status", Static).render())


@sync
async def test_a_decline_needs_a_note_and_the_student_reads_it(tmp_path):
    data = tmp_path / "data"
    create_instructor(data, "Dr Chen", PASS, kdf=FAST)
    with Store.open(data) as store:
        save_student(store, "cat", passed=False)
        store.queue.request("cat", "", "cat", LAB, EXERCISE)
    app = console(data)
    async with app.run_test(size=(80, 24)) as pilot:
        await until(lambda: len(queue_lines(app)) == 1, "the request")
        await pilot.press("enter")
        request = app.screen
        await until(lambda: request.request is not None, "the saved progress")
        assert "2 of 3 objectives pass" in "\n".join(screen_lines(app))
        await pilot.press("ctrl+d")
        assert "write a note first" in status(request)
        await pilot.press(*"answer the last question", "ctrl+d")
        await until(lambda: isinstance(app.screen, ConsoleScreen), "the console")
        await until(lambda: queue_lines(app) == [], "the queue emptied")
        assert "declined cat" in str(app.screen.query_one("#console-message").render())
    with Store.open(data) as store:
        entry = store.queue.state("cat", LAB, EXERCISE).entry
        assert store.signoffs.of() == []
    assert entry.state == DECLINED and entry.note == "answer the last question"
    assert entry.instructor == "Dr Chen"


@sync
async def test_signing_work_that_does_not_pass_needs_the_override_and_a_note(tmp_path):
    data = tmp_path / "data"
    create_instructor(data, "Dr Chen", PASS, kdf=FAST)
    with Store.open(data) as store:
        save_student(store, "cat", passed=False)
        store.queue.request("cat", "", "cat", LAB, EXERCISE)
    app = console(data)
    async with app.run_test(size=(80, 24)) as pilot:
        await until(lambda: len(queue_lines(app)) == 1, "the request")
        await pilot.press("enter")
        request = app.screen
        await until(lambda: request.request is not None, "the saved progress")
        await pilot.press(*PASS, "enter")
        await until(lambda: "override" in status(request), "the refusal")
    with Store.open(data) as store:
        assert store.signoffs.of() == [] and len(store.queue.waiting()) == 1


def objectives_text(request: RequestScreen) -> str:
    """The request's objectives and evidence, unwrapped (as one line of words)."""
    return " ".join(str(request.query_one("#request-objectives", Static).render()).split())


async def open_request(app: ConsoleApp, pilot) -> RequestScreen:
    await until(lambda: len(queue_lines(app)) == 1, "the request")
    await pilot.press("enter")
    request = app.screen
    assert isinstance(request, RequestScreen)
    await until(lambda: request.request is not None, "the saved progress")
    await pilot.pause()
    return request


@sync
async def test_the_evidence_says_the_run_program_sensors_measures_and_tries(tmp_path):
    data = tmp_path / "data"
    progress = wall_main("ana")
    questions = progress.objectives[2]
    questions.evidence["waiting"] = ["margin"]
    with Store.open(data) as store:
        save_progress(store, "ana", progress)
        store.queue.request("ana", "", "ana", WEB_LAB, WALL_MAIN)
    app = console(data)
    async with app.run_test(size=(80, 24)) as pilot:
        request = await open_request(app, pilot)
        said = objectives_text(request)
        # the Web profile's distance in blocks and whole pixels, not "4245.42 m"
        assert "out in 61.2 s, 60.65 blocks (4245 px), turned 1980 deg, 22 turns, " in said
        assert "1 collision, 9 touches" in said and "4245.42" not in said and " m," not in said
        assert "run 4 by VIPLE program wall.viple (ana at the station) on Web" in said
        assert "program wall.viple (sha256 abababababab); sensors distance:1:right, " in said
        assert "2 of 2 right; tries: base 1, margin 3" in said
        assert "waiting for you (no tries left): margin" in said
        assert "reached_exit" not in said and "sim_time" not in said
        # wrapped lines stay indented under their objective, inside 80 columns
        lines = screen_lines(app)
        assert all(len(line.rstrip()) <= 80 for line in lines)
        assert any(line.startswith("       lab maze (web)") for line in lines)


@sync
async def test_evidence_on_two_programs_and_a_program_two_students_share_are_marked(tmp_path):
    data = tmp_path / "data"
    with Store.open(data) as store:
        mixed = wall_main("ana", sensors_program=("other.viple", "cd" * 32))
        save_progress(store, "ana", mixed)
        save_progress(store, "ben", wall_main("ben", attempt="att-2"))
        save_progress(store, "cat", wall_main("cat", digest="ef" * 32, attempt="att-3"))
        store.queue.request("ana", "", "ana", WEB_LAB, WALL_MAIN)
    app = console(data)
    async with app.run_test(size=(80, 24)) as pilot:
        await until(lambda: len(class_lines(app)) == 3, "the class")
        ana, ben, cat = class_lines(app)
        assert "! evidence mixes 2 programs; same program as ben" in ana
        assert ben.endswith("! same program as ana") and "!" not in cat
        request = await open_request(app, pilot)
        said = objectives_text(request)
        assert (
            "! the evidence mixes 2 programs: wall.viple (abababababab), other.viple "
            "(cdcdcdcdcdcd)" in said
        )
        assert "! same program as ben: wall.viple (sha256 abababababab)" in said


@sync
async def test_a_pair_and_the_bundled_programs_are_no_copy_hint(tmp_path):
    from workbench.labs.copy_hints import bundled_digests
    from workbench.sim.record import file_sha256

    bundled = file_sha256("programs/web-wall-following.viple")
    assert bundled in bundled_digests()
    data = tmp_path / "data"
    with Store.open(data) as store:
        # ana and ben worked as a pair at one station (one attempt); dan and eve each ran the
        # program the workbench ships
        save_progress(store, "ana", wall_main("ana"))
        save_progress(store, "ben", wall_main("ana"))
        for name in ("dan", "eve"):
            shipped = wall_main(name, "web-wall-following.viple", bundled, f"att-{name}")
            save_progress(store, name, shipped)
    app = console(data)
    async with app.run_test(size=(80, 24)):
        await until(lambda: len(class_lines(app)) == 4, "the class")
        assert not any("!" in line for line in class_lines(app))
        assert app.screen.view.hints == ()


@sync
async def test_long_exercise_ids_are_shown_whole_at_80_columns(tmp_path):
    data = tmp_path / "data"
    lab, exercise = LONG_EXERCISE
    with Store.open(data) as store:
        store.progress.set_place("a-student-with-a-long-name", lab, exercise)
        store.queue.request("a-student-with-a-long-name", "her-partner", "her-partner",
                              lab, exercise)  # fmt: skip
    app = console(data)
    async with app.run_test(size=(80, 24)):
        await until(lambda: len(queue_lines(app)) == 1, "the request")
        shown = "\n".join(screen_lines(app))
        assert f"{lab}/{exercise}" in shown  # not "reading-wall-f"
        assert "a-student-with-a-long-name and her-partner" in shown
        assert all(len(line.rstrip()) <= 80 for line in screen_lines(app))


@sync
async def test_the_replay_from_the_console_draws_in_ascii(tmp_path):
    data = tmp_path / "data"
    record = write_record(tmp_path / "run-003.jsonl")
    with Store.open(data) as store:
        save_student(store, "ana", record=str(record))
        store.queue.request("ana", "", "ana", LAB, EXERCISE)
    app = console(data)
    async with app.run_test(size=(80, 24)) as pilot:
        request = await open_request(app, pilot)
        await pilot.click("#request-replay")
        await until(lambda: isinstance(app.screen, ReplayScreen), "the replay")
        await pilot.pause()
        lines = screen_lines(app)
        assert any("left/right step" in line for line in lines)
        assert all(line.isascii() for line in lines), [x for x in lines if not x.isascii()]
        await pilot.press("escape")
        await until(lambda: app.screen is request, "back from the replay")
