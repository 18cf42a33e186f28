"""Answers, names and notes have a length cap: text past it is cut with a message, and an
oversized answer already in the store is read back cut, with a notice (never a frozen screen)."""

from __future__ import annotations

from textual import events
from textual.pilot import Pilot
from textual.widgets import Input

from workbench.labs.checks import MAX_ANSWER, ExerciseProgress
from workbench.labs.names import MAX_STUDENT_NAME
from workbench.labs.store.store import Store
from workbench.tui.app import make_app
from workbench.tui.dialogs.identity import IdentityDialog
from workbench.wire.settings import AppSettings

from .labs_support import DRIVE, lab_app, open_exercise, text
from .support import run

HUGE = "9" * (8 << 20)  # 8 MiB


def test_a_pasted_huge_answer_is_cut_to_the_cap_with_a_message(tmp_path):
    app = lab_app(tmp_path / "data")

    async def body(pilot: Pilot) -> None:
        screen = await open_exercise(pilot, DRIVE)
        field = screen.query_one("#q-tcp-port", Input)
        field.focus()
        field.post_message(events.Paste(HUGE))
        await pilot.pause()
        assert len(field.value) == MAX_ANSWER
        assert text(screen, "#labs-message") == (
            f"an answer is at most {MAX_ANSWER} characters: the rest was not kept"
        )
        await pilot.press("end", "backspace", "backspace", "enter")  # it still edits; tried
        assert len(field.value) == MAX_ANSWER - 2
        saved = app.store.progress.of("ana")[("unity-simulator", "drive-by-wire")]
        assert len(saved["answers"]["tcp-port"]) == MAX_ANSWER - 2

    run(app, body)


def test_an_oversized_answer_in_the_store_is_read_back_cut_with_a_notice(tmp_path):
    data = tmp_path / "data"
    with Store.open(data) as store:
        store.progress.save(
            "ana",
            "unity-simulator",
            "drive-by-wire",
            {
                "lab": "unity-simulator",
                "exercise": "drive-by-wire",
                "objectives": [],
                "answers": {"tcp-port": HUGE},
            },
        )
    app = lab_app(data)

    async def body(pilot: Pilot) -> None:
        screen = await open_exercise(pilot, DRIVE)
        field = screen.query_one("#q-tcp-port", Input)
        assert field.value == "9" * MAX_ANSWER
        assert text(screen, "#labs-message") == (
            f"saved answers longer than {MAX_ANSWER} characters were cut to their first "
            f"{MAX_ANSWER}: unity-simulator/drive-by-wire tcp-port"
        )
        field.value = ""
        field.focus()
        await pilot.press("1", "3", "5", "0", "enter")
        saved = app.store.progress.of("ana")[("unity-simulator", "drive-by-wire")]
        assert saved["answers"]["tcp-port"] == "1350"

    run(app, body)


def test_progress_keeps_answers_within_the_cap_however_it_is_made():
    progress = ExerciseProgress("lab", "ex", [], {"q": HUGE, "r": "42"})
    assert progress.answers == {"q": "9" * MAX_ANSWER, "r": "42"}
    assert progress.cut == ("q",)
    assert len(progress.to_json()) < 1000


def test_a_name_past_the_cap_is_cut_with_a_message(tmp_path):
    app = make_app(AppSettings(paused=True, student="ana", data_dir=tmp_path, ask_names=True))

    async def body(pilot: Pilot) -> None:
        partner = app.screen.query_one("#partner", Input)
        partner.focus()
        partner.post_message(events.Paste("Ben" * 1000))
        await pilot.pause()
        assert len(partner.value) == MAX_STUDENT_NAME
        assert isinstance(app.screen, IdentityDialog)
        assert text(app.screen, "#error") == (
            f"a name is at most {MAX_STUDENT_NAME} characters: the rest was not kept"
        )

    run(app, body)
