"""What the labs screen tests share: an app for a pair, opening an exercise, reading a line."""

from __future__ import annotations

from pathlib import Path

from textual.pilot import Pilot
from textual.widgets import Input, OptionList, Static

from tests.waiting import until
from workbench.tui.app import WorkbenchApp, make_app
from workbench.tui.dialogs.signoff import SignoffModal
from workbench.tui.screens.labs import LabsScreen
from workbench.wire.settings import AppSettings

DRIVE = "unity-simulator/drive-by-wire"


def lab_app(data_dir: Path, **kw) -> WorkbenchApp:
    """The app, paused, for the pair ana and ben, keeping its data in ``data_dir``."""
    return make_app(AppSettings(paused=True, student="ana", partner="ben", data_dir=data_dir, **kw))


def text(screen, selector: str) -> str:
    return str(screen.query_one(selector, Static).render())


def objective_lines(screen) -> list[str]:
    """The objectives' lines of the labs screen (mark, text and reason), without the lines of
    evidence under the passed ones."""
    lines = text(screen, "#labs-objectives").splitlines()
    return [line for line in lines if line and not line.startswith(" ")]


def evidence_lines(screen) -> list[str]:
    """The lines under the passed objectives that say what each pass rests on."""
    lines = text(screen, "#labs-objectives").splitlines()
    return [line.strip() for line in lines if line.startswith(" ")]


async def open_labs(pilot: Pilot) -> LabsScreen:
    """``l``, and the labs screen once it has read the saved work (from a thread)."""
    await pilot.press("l")
    screen = pilot.app.screen
    assert isinstance(screen, LabsScreen)
    await until(lambda: not screen.lab_progress.reading, "the saved work read")
    await pilot.pause()
    return screen


async def open_exercise(pilot: Pilot, option_id: str = DRIVE) -> LabsScreen:
    """``l``, then the exercise ``option_id`` ("lab/exercise") highlighted in the list."""
    screen = await open_labs(pilot)
    listing = screen.query_one("#labs-list", OptionList)
    listing.highlighted = listing.get_option_index(option_id)
    await pilot.pause()
    return screen


async def signing_over(pilot: Pilot, modal: SignoffModal) -> None:
    """Wait until the sign-off the dialog started (its key unlocked in a thread) is over:
    signed, or refused with the reason shown."""
    if modal.signing is not None:
        await modal.signing.wait()
    await pilot.pause()


def try_answer(screen, question_id: str, answer: str) -> None:
    """``answer`` typed into the field of ``question_id`` and tried, as enter there tries it
    (the focus stays where it is); the try is taken once the app has handled its message."""
    field = screen.query_one(f"#q-{question_id}", Input)
    field.value = answer
    field.post_message(Input.Submitted(field, answer))
