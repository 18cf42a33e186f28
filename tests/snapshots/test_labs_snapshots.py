"""SVG snapshots of the labs screen, the sign-off dialog and the driver-change prompt at 80x24.

The app is paused, the student and partner are named, the data folder is a fresh temporary
one, input cursors do not blink and buttons are pressed by keys, so the pictures are the same
on every run.
"""

from __future__ import annotations

from datetime import UTC, datetime

import pytest
from textual.pilot import Pilot
from textual.widgets import Checkbox, Input, OptionList

from tests.app.labs_support import lab_app, open_labs, signing_over
from tests.app.support import still
from workbench.labs.model import load_labs
from workbench.labs.signoff.instructors import KdfParams, create_instructor
from workbench.tui.app import make_app
from workbench.wire.settings import AppSettings

FAST = KdfParams(n=2**10, r=8, p=1)  # cheap scrypt for tests only
PASS = "correct horse battery"
SIZE = (80, 24)


async def open_drive_by_wire(pilot: Pilot) -> None:
    await open_labs(pilot)
    listing = pilot.app.screen.query_one("#labs-list", OptionList)
    listing.highlighted = listing.get_option_index("unity-simulator/drive-by-wire")
    await pilot.pause()
    await pilot.press("a")
    await pilot.press("escape", "w", "a", "s", "d", "space", "l")
    await pilot.pause()
    still(pilot)
    await pilot.pause()


def test_labs_exercise_with_objectives_in_both_states(snap_compare, tmp_path):
    app = lab_app(tmp_path / "data")
    assert snap_compare(app, terminal_size=SIZE, run_before=open_drive_by_wire)


def test_signoff_dialog(snap_compare, tmp_path):
    async def before(pilot: Pilot) -> None:
        await open_drive_by_wire(pilot)
        await pilot.press("i")
        await pilot.pause()
        still(pilot)
        await pilot.pause()

    create_instructor(tmp_path / "data", "Dr Chen", PASS, kdf=FAST)
    assert snap_compare(lab_app(tmp_path / "data"), terminal_size=SIZE, run_before=before)


class SigningTime(datetime):
    """The clock of the sign-off, at one fixed moment: the labs screen behind the dialog shows
    the sign-off's time as soon as it is saved."""

    @classmethod
    def now(cls, tz=None):  # type: ignore[override]
        return datetime(2026, 3, 2, 10, 0, tzinfo=UTC)


def test_driver_change_prompt_after_an_override(snap_compare, tmp_path, monkeypatch):
    monkeypatch.setattr("workbench.labs.signoff.signing.datetime", SigningTime)

    async def before(pilot: Pilot) -> None:
        await open_drive_by_wire(pilot)
        await pilot.press("i")
        await pilot.pause()
        modal = pilot.app.screen
        modal.query_one("#signoff-override", Checkbox).value = True
        modal.query_one("#signoff-note", Input).value = "showed it on the lab robot"
        field = modal.query_one("#signoff-passphrase", Input)
        field.value = PASS
        field.focus()
        await pilot.press("enter")
        await signing_over(pilot, modal)
        still(pilot)
        await pilot.pause()

    create_instructor(tmp_path / "data", "Dr Chen", PASS, kdf=FAST)
    assert snap_compare(lab_app(tmp_path / "data"), terminal_size=SIZE, run_before=before)


def test_names_dialog_at_start(snap_compare, tmp_path):
    app = make_app(
        AppSettings(paused=True, student="ana", data_dir=tmp_path / "data", ask_names=True)
    )

    async def before(pilot: Pilot) -> None:
        await pilot.pause()
        pilot.app.screen.query_one("#partner", Input).value = "Ben Ortiz"
        still(pilot)
        await pilot.pause()

    assert snap_compare(app, terminal_size=SIZE, run_before=before)


LABS = load_labs()
EXERCISES = [f"{lab.id}/{ex.id}" for lab in LABS for ex in lab.exercises]


@pytest.mark.parametrize("option_id", EXERCISES, ids=[o.replace("/", ".") for o in EXERCISES])
def test_every_lab_exercise_at_80x24(snap_compare, tmp_path, option_id):
    """Each exercise as a pair first sees it: chosen in the list, not set up, ASCII marks."""

    async def before(pilot: Pilot) -> None:
        await open_labs(pilot)
        listing = pilot.app.screen.query_one("#labs-list", OptionList)
        listing.highlighted = listing.get_option_index(option_id)
        await pilot.pause()
        still(pilot)
        await pilot.pause()

    app = lab_app(tmp_path / "data")
    assert snap_compare(app, terminal_size=SIZE, run_before=before)


def test_multiple_choice_question_at_80x24(snap_compare, tmp_path):
    """A multiple-choice question moved to with the keys, its second choice picked: every
    choice whole (the long one wrapped under its text), the picked one marked (*)."""

    async def before(pilot: Pilot) -> None:
        await open_labs(pilot)
        screen = pilot.app.screen
        listing = screen.query_one("#labs-list", OptionList)
        listing.highlighted = listing.get_option_index("maze-algorithms/erobotic-rules")
        await pilot.pause()
        choices = screen.query_one("#q-why-no-states")
        choices.focus()
        await pilot.pause()
        await pilot.press("down", "enter")
        screen.query_one("#labs-scroll").scroll_end(animate=False)
        await pilot.pause()
        still(pilot)
        await pilot.pause()

    app = lab_app(tmp_path / "data")
    assert snap_compare(app, terminal_size=SIZE, run_before=before)
