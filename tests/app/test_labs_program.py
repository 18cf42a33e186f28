"""A lab exercise done with the student's own VIPLE program, end to end through the labs screen:
set up, load the program, run it out of the maze, see the objective pass, sign it off; the
evidence and the signed record name the program by its sha256."""

from __future__ import annotations

import hashlib
from pathlib import Path

from textual.pilot import Pilot
from textual.widgets import Input

from tests.students_work import own_right_wall
from workbench.labs.signoff.instructors import KdfParams, create_instructor
from workbench.labs.store.store import Store
from workbench.tui.dialogs.algorithm import AlgorithmModal
from workbench.tui.dialogs.signoff import SignoffModal

from .labs_support import lab_app, open_exercise, signing_over, text, try_answer
from .support import run

EXAMPLE = Path(__file__).resolve().parents[2] / "programs" / "web-wall-following.viple"
EXERCISE = "web-simulator/wall-activities"
FAST = KdfParams(n=2**10, r=8, p=1)  # cheap scrypt for tests only
PASS = "correct horse battery"


def test_a_viple_exercise_is_passed_and_signed_off_with_the_students_program(tmp_path):
    data = tmp_path / "data"
    create_instructor(data, "Dr Chen", PASS, kdf=FAST)
    app = lab_app(data)
    mine = own_right_wall(tmp_path)
    digest = hashlib.sha256(mine.read_bytes()).hexdigest()

    async def body(pilot: Pilot) -> None:
        station = app.station
        screen = await open_exercise(pilot, EXERCISE)
        await pilot.press("a")  # the exercise's profile, maze and sensors
        assert "set up: web" in text(screen, "#labs-message")
        objectives = text(screen, "#labs-objectives").splitlines()
        assert objectives[0].startswith("[ ] your program got out of the Web maze within 300 s")
        await pilot.press("escape", "g")
        await pilot.pause()
        dialog = app.screen
        assert isinstance(dialog, AlgorithmModal)
        dialog.query_one("#alg-path", Input).value = str(mine)
        await dialog.choose(str(mine))
        await pilot.press("escape")
        await pilot.press("x")  # the program drives from the start block
        station.pause()
        for _ in range(300):  # at most 300 simulated seconds, a second at a time
            station.step(60)
            if station.runs and station.runs[-1].ended == "exit":
                break
        app.refresh_views()
        await pilot.press("l")
        await pilot.pause()
        objectives = text(screen, "#labs-objectives").splitlines()
        assert objectives[0].startswith("[X] your program got out of the Web maze within 300 s")
        assert "VIPLE program my-right-wall.viple" in objectives[0]
        progress = app.store.progress.of("ana")[("web-simulator", "wall-activities")]
        evidence = progress["objectives"][0]["evidence"]
        assert evidence["program_sha256"] == digest
        assert evidence["driver"] == "VIPLE program my-right-wall.viple"
        assert evidence["program_name"] == "my-right-wall.viple"
        assert evidence["sensors"] == ["distance:1:right", "touch:2:front"]
        answers = (("backward", "-0.3"), ("forward", "0.5"), ("spin-ms", "1500"))
        for question, answer in answers:  # the exercise's questions, as the text tells them
            try_answer(screen, question, answer)
        await pilot.pause()
        assert screen.progress is not None and screen.progress.passed, screen.progress
        await pilot.press("i")
        await pilot.pause()
        modal = app.screen
        assert isinstance(modal, SignoffModal)
        field = modal.query_one("#signoff-passphrase", Input)
        field.value = PASS
        field.focus()
        await pilot.press("enter")
        await signing_over(pilot, modal)
        assert "Signed off by Dr Chen" in text(modal, "#signoff-done")
        with Store.open(data) as store:
            (row,) = store.signoffs.of(student="ana")
        assert (row.lab, row.exercise) == ("web-simulator", "wall-activities")
        assert row.evidence_digest == screen.progress.evidence_digest()
        # the signed record names the program the evidence rests on
        assert row.metrics_value()["programs"] == {digest: "my-right-wall.viple"}

    run(app, body)


def test_the_example_program_that_solves_the_exercise_does_not_pass_it(tmp_path):
    app = lab_app(tmp_path / "data")

    async def body(pilot: Pilot) -> None:
        station = app.station
        screen = await open_exercise(pilot, EXERCISE)
        await pilot.press("a")
        await pilot.press("escape", "g")
        await pilot.pause()
        dialog = app.screen
        assert isinstance(dialog, AlgorithmModal)
        dialog.query_one("#alg-path", Input).value = str(EXAMPLE)
        await dialog.choose(str(EXAMPLE))
        await pilot.press("escape")
        await pilot.press("x")
        station.pause()
        for _ in range(300):
            station.step(60)
            if station.runs and station.runs[-1].ended == "exit":
                break
        assert station.runs[-1].ended == "exit"  # it does get out
        app.refresh_views()
        await pilot.press("l")
        await pilot.pause()
        objectives = text(screen, "#labs-objectives")
        assert objectives.startswith(
            "[ ] your program got out of the Web maze within 300 s: run 1 (VIPLE program "
            "web-wall-following.viple) is the example program programs/web-wall-following.viple,"
            " which comes with the workbench, not your own program"
        ), objectives

    run(app, body)
