"""The labs screen and the sign-off dialog, driven with a Pilot."""

from __future__ import annotations

import asyncio
import threading

import pytest
from textual.pilot import Pilot
from textual.widgets import Button, Checkbox, Input, OptionList, Select, Static

from workbench.cli import build_parser
from workbench.labs.signoff.instructors import KdfParams, SealedKey, create_instructor
from workbench.labs.signoff.signing import FAILURE_LIMIT, sign_off
from workbench.labs.signoff.signoff_errors import WrongPassphrase
from workbench.labs.signoff.signoff_record import RecordFields
from workbench.labs.store.store import Store
from workbench.tui.dialogs.signoff import SignoffModal
from workbench.tui.screens.labs import LabsScreen
from workbench.tui.screens.main import MainScreen

from .labs_support import (
    DRIVE,
    lab_app,
    objective_lines,
    open_exercise,
    signing_over,
    text,
    try_answer,
)
from .support import run

FAST = KdfParams(n=2**10, r=8, p=1)  # cheap scrypt for tests only
PASS = "correct horse battery"


async def complete_drive_by_wire(pilot: Pilot, screen: LabsScreen) -> None:
    """Everything drive-by-wire asks: the five keys, an edited maze, the TCP port."""
    await pilot.press("a")  # the set-up
    await pilot.press("escape")
    await pilot.press("w", "a", "s", "d", "space")
    station = pilot.app.station
    maze = station.maze
    inner = next((x, y) for y in range(1, maze.height - 1) for x in range(1, maze.width - 1)
                 if maze.is_wall(x, y))  # fmt: skip
    # the editor's report of one block taken away by hand
    station.put_edited_maze(maze.with_block(*inner, wall=False), maze, hand_blocks=1)
    await pilot.press("l")
    await pilot.pause()
    try_answer(screen, "tcp-port", "1350")
    await pilot.pause()


def test_l_opens_the_labs_and_escape_goes_back(tmp_path):
    app = lab_app(tmp_path / "data")

    async def body(pilot: Pilot) -> None:
        screen = await open_exercise(pilot)
        ids = [o.id for o in screen.query_one("#labs-list", OptionList).options]
        assert "lab:unity-simulator" in ids and DRIVE in ids
        assert "web-simulator/placing-sensors" in ids or len(ids) > 12
        assert text(screen, "#labs-title") == "Unity simulator: Drive by wire"
        await pilot.press("escape")
        assert isinstance(app.screen, MainScreen)

    run(app, body)


def test_set_up_then_driving_flips_the_keys_objective_and_saves_progress(tmp_path):
    data = tmp_path / "data"
    app = lab_app(data, profile="web")

    async def body(pilot: Pilot) -> None:
        screen = await open_exercise(pilot)
        assert text(screen, "#labs-objectives").startswith("[ ] drove with w, a, s, d and space")
        await pilot.press("a")
        assert app.station.profile == "unity"
        assert "set up: unity" in text(screen, "#labs-message")
        await pilot.press("escape")
        await pilot.press("w", "a", "s", "d", "space")
        await pilot.pause()
        progress = app.store.progress.of("ana")[("unity-simulator", "drive-by-wire")]
        assert progress["objectives"][0]["passed"] is True  # saved while the labs were closed
        await pilot.press("l")
        await pilot.pause()
        lines = objective_lines(screen)
        assert lines[0].startswith("[X] drove with w, a, s, d and space")
        assert lines[1].startswith("[ ] edited the maze")

    run(app, body)


def test_a_question_is_checked_when_an_answer_is_tried_and_every_try_counts(tmp_path):
    app = lab_app(tmp_path / "data")

    async def body(pilot: Pilot) -> None:
        screen = await open_exercise(pilot)
        reason = screen.query_one(".question-reason", Static)
        assert str(reason.render()) == "not answered yet"
        screen.query_one("#q-tcp-port", Input).focus()
        await pilot.press("1", "3", "5", "1")
        await pilot.pause()
        # typing is not trying: nothing is checked (or counted) before enter
        assert str(reason.render()) == "press enter to try this answer"
        assert "[ ] question answered: not answered yet" in text(screen, "#labs-objectives")
        await pilot.press("enter")
        await pilot.pause()
        assert str(reason.render()) == "[ ] not the expected answer (1 try)"
        await pilot.press("backspace", "0", "enter")
        await pilot.pause()
        assert str(reason.render()) == "[X] correct (2 tries)"
        assert "[X] question answered" in text(screen, "#labs-objectives")
        assert "  1 of 1 right; tries: tcp-port 2" in text(screen, "#labs-objectives")
        saved = app.store.progress.of("ana")[("unity-simulator", "drive-by-wire")]
        assert saved["answers"] == {"tcp-port": "1350"}
        assert saved["tries"] == {"tcp-port": 2}

    run(app, body)


def test_sign_off_happy_path_then_the_driver_changes(tmp_path):
    data = tmp_path / "data"
    create_instructor(data, "Dr Chen", PASS, kdf=FAST)
    app = lab_app(data)

    async def body(pilot: Pilot) -> None:
        screen = await open_exercise(pilot)
        await complete_drive_by_wire(pilot, screen)
        assert screen.progress is not None and screen.progress.passed
        await pilot.press("i")
        await pilot.pause()
        modal = app.screen
        assert isinstance(modal, SignoffModal)
        assert modal.query_one("#signoff-instructor", Select).value == "Dr Chen"
        field = modal.query_one("#signoff-passphrase", Input)
        assert field.password
        field.value = PASS
        field.focus()
        await pilot.press("enter")
        await signing_over(pilot, modal)
        assert "Signed off by Dr Chen" in text(modal, "#signoff-done")
        await pilot.click("#signoff-driver-1")
        await pilot.pause()
        assert app.screen is screen
        assert screen.driver == "ben"
        assert text(screen, "#labs-message") == "signed off; ben drives next"
        with Store.open(data) as store:
            (row,) = store.signoffs.of(student="ana")
            drivers = store.progress.drivers("ana", "ben")
        assert (row.lab, row.exercise, row.driver, row.override) == (
            "unity-simulator",
            "drive-by-wire",
            "ana",
            False,
        )
        assert row.evidence_digest == screen.progress.evidence_digest()
        assert drivers[("unity-simulator", "drive-by-wire")] == "ana"
        assert drivers[("unity-simulator", "reading-wall-following")] == "ben"
        listing = screen.query_one("#labs-list", OptionList)
        option = listing.get_option(DRIVE)
        assert str(option.prompt).startswith("[*]")  # signed off, apart from only passed

    run(app, body)

    again = lab_app(data)

    async def later(pilot: Pilot) -> None:
        screen = await open_exercise(pilot, DRIVE)
        assert screen.driver == "ana"  # who drove it, from the store
        assert str(screen.query_one("#labs-list", OptionList).get_option(DRIVE).prompt).startswith(
            "[*]"
        )
        title = str(screen.query_one("#labs-title").render())
        assert "[*] signed off by " in title  # by whom and when
        await pilot.press("i")
        await pilot.pause()
        assert "Already signed off by " in str(
            pilot.app.screen.query_one("#signoff-already").render()
        )
        await pilot.press("escape")
        await open_exercise(pilot, "unity-simulator/reading-wall-following")
        assert screen.driver == "ben"

    run(again, later)


def test_a_wrong_passphrase_is_shown_and_nothing_is_signed(tmp_path):
    data = tmp_path / "data"
    create_instructor(data, "Dr Chen", PASS, kdf=FAST)
    app = lab_app(data)

    async def body(pilot: Pilot) -> None:
        screen = await open_exercise(pilot)
        await complete_drive_by_wire(pilot, screen)
        await pilot.press("i")
        await pilot.pause()
        modal = app.screen
        modal.query_one("#signoff-passphrase", Input).value = "not the passphrase"
        await pilot.click("#signoff-sign")
        await signing_over(pilot, modal)
        assert text(modal, "#signoff-status") == "wrong passphrase for Dr Chen"
        assert modal.query_one("#signoff-passphrase", Input).value == ""
        assert app.store.signoffs.of() == []
        await pilot.press("escape")
        assert app.screen is screen

    run(app, body)


def test_a_locked_out_instructor_is_told_for_how_long(tmp_path):
    data = tmp_path / "data"
    create_instructor(data, "Dr Chen", PASS, kdf=FAST)
    fields = RecordFields("ana", "unity-simulator", "drive-by-wire", objectives_passed=True)
    with Store.open(data) as store:
        for _ in range(FAILURE_LIMIT - 1):
            with pytest.raises(WrongPassphrase):
                sign_off(store, "Dr Chen", "not the passphrase", fields)
    app = lab_app(data)

    async def body(pilot: Pilot) -> None:
        await open_exercise(pilot)
        await pilot.press("i")
        await pilot.pause()
        modal = app.screen
        modal.query_one("#signoff-override", Checkbox).value = True
        modal.query_one("#signoff-note", Input).value = "checked by hand"
        field = modal.query_one("#signoff-passphrase", Input)
        field.value = "still not the passphrase"
        field.focus()
        await pilot.press("enter")
        await signing_over(pilot, modal)
        assert text(modal, "#signoff-status").startswith(
            "sign-off by Dr Chen is locked for 60 s more"
        )
        field.value = PASS
        await pilot.press("enter")
        await signing_over(pilot, modal)
        assert "is locked for" in text(modal, "#signoff-status")
        assert app.store.signoffs.of() == []

    run(app, body)


def test_the_app_keeps_answering_while_the_key_is_unlocked(tmp_path, monkeypatch):
    """scrypt runs in a thread: while it works the dialog says so, typed keys arrive, a
    second enter starts no second sign-off, and escape closes once the sign-off is done."""
    data = tmp_path / "data"
    create_instructor(data, "Dr Chen", PASS, kdf=FAST)
    unlocking, release = threading.Event(), threading.Event()
    unlocks = []
    unlock = SealedKey.unlock

    def held(key: SealedKey, passphrase: str):
        unlocks.append(key.name)
        unlocking.set()
        if threading.current_thread() is threading.main_thread():
            raise AssertionError("the key is unlocked on the event loop")
        release.wait(timeout=60)
        return unlock(key, passphrase)

    monkeypatch.setattr(SealedKey, "unlock", held)
    app = lab_app(data)

    async def body(pilot: Pilot) -> None:
        screen = await open_exercise(pilot)
        await complete_drive_by_wire(pilot, screen)
        await pilot.press("i")
        await pilot.pause()
        modal = app.screen
        assert isinstance(modal, SignoffModal)
        field = modal.query_one("#signoff-passphrase", Input)
        field.value = PASS
        field.focus()
        await pilot.press("enter")
        await asyncio.to_thread(unlocking.wait, 60)
        assert text(modal, "#signoff-status") == "unlocking the key of Dr Chen..."
        note = modal.query_one("#signoff-note", Input)
        note.focus()
        await pilot.press("o", "k")
        assert note.value == "ok"  # keys typed while the key is unlocked arrive
        await pilot.press("enter")  # a second enter while the first sign-off is under way
        await pilot.press("escape")
        assert app.screen is modal
        assert text(modal, "#signoff-status") == "closing once the key is unlocked..."
        release.set()
        await signing_over(pilot, modal)
        assert app.screen is screen  # closed once signed, the driver kept
        assert unlocks == ["Dr Chen"]
        (row,) = app.store.signoffs.of(student="ana")
        assert row.instructor == "Dr Chen" and not row.note
        assert text(screen, "#labs-message") == "signed off; ana drives next"

    run(app, body)


def test_the_command_line_names_the_student_partner_and_data_folder():
    args = build_parser().parse_args(["--student", "ana", "--partner", "ben", "--data-dir", "d"])
    assert (args.student, args.partner, args.data_dir) == ("ana", "ben", "d")
    args = build_parser().parse_args([])
    assert (args.student, args.partner, args.data_dir) == (None, "", None)


def test_an_override_without_a_note_is_refused(tmp_path):
    data = tmp_path / "data"
    create_instructor(data, "Dr Chen", PASS, kdf=FAST)
    app = lab_app(data)

    async def body(pilot: Pilot) -> None:
        await open_exercise(pilot)
        await pilot.press("i")
        await pilot.pause()
        modal = app.screen
        assert "override is needed" in text(modal, "#signoff-state")
        note = modal.query_one("#signoff-note", Input)
        modal.query_one("#signoff-passphrase", Input).value = PASS
        note.focus()
        await pilot.press("enter")  # as the Sign off button does
        await signing_over(pilot, modal)
        assert "sign off with an override" in text(modal, "#signoff-status")
        modal.query_one("#signoff-override", Checkbox).value = True
        modal.query_one("#signoff-passphrase", Input).value = PASS
        await pilot.press("enter")
        await signing_over(pilot, modal)
        assert text(modal, "#signoff-status") == "an override needs a note saying why"
        note.value = "showed it on the lab robot"
        modal.query_one("#signoff-passphrase", Input).value = PASS
        await pilot.press("enter")
        await signing_over(pilot, modal)
        assert "(override)" in text(modal, "#signoff-done")
        (row,) = app.store.signoffs.of()
        assert row.override and row.note == "showed it on the lab robot"

    run(app, body)


def test_without_a_roster_the_dialog_says_how_to_add_an_instructor(tmp_path):
    app = lab_app(tmp_path / "data")

    async def body(pilot: Pilot) -> None:
        await open_exercise(pilot)
        await pilot.press("i")
        await pilot.pause()
        modal = app.screen
        assert "workbench instructor add NAME" in text(modal, "#signoff-status")
        await pilot.click("#signoff-sign")
        assert isinstance(app.screen, SignoffModal)
        assert not modal.query_one("#signoff-next").display
        assert isinstance(modal.query_one("#signoff-cancel"), Button)

    run(app, body)


def test_a_data_folder_that_cannot_open_is_reported_and_the_labs_still_work(tmp_path):
    blocker = tmp_path / "file"
    blocker.write_text("not a folder")
    app = lab_app(blocker)

    async def body(pilot: Pilot) -> None:
        screen = await open_exercise(pilot)
        assert app.store is None
        assert text(screen, "#labs-message").startswith("cannot open the data folder")
        await pilot.press("a")
        assert app.station.profile == "unity"
        await pilot.press("i")
        assert app.screen is screen
        assert "cannot open the data folder" in text(screen, "#labs-message")

    run(app, body)


def test_every_objective_is_reachable_at_80x24(tmp_path):
    app = lab_app(tmp_path / "data")

    async def body(pilot: Pilot) -> None:
        screen = await open_exercise(pilot, "unity-simulator/wall-following")
        objectives = screen.query_one("#labs-objectives", Static)
        lines = [line for line in text(screen, "#labs-objectives").splitlines() if line]
        assert len(lines) == len(screen.selected[1].objectives) == 4
        # the objectives are not cut: the box is as tall as its wrapped text, and it scrolls
        # with the instructions, so the last one can be brought on screen
        assert objectives.size.height >= len(lines)
        assert objectives.parent is screen.query_one("#labs-scroll")
        screen.query_one("#labs-scroll").scroll_to_widget(objectives, top=True, animate=False)
        await pilot.pause()
        assert objectives.region.bottom <= pilot.app.size.height

    run(app, body, size=(80, 24))
