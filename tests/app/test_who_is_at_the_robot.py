"""Who is at the robot: the app offers the last pair at this workbench, and a name typed with
other case or spacing resumes the progress saved under it; a served student only ever gets
the login's own name."""

from __future__ import annotations

from dataclasses import replace

from textual.pilot import Pilot
from textual.widgets import Input

from workbench.labs.lastpair import save_last_pair
from workbench.tui.app import make_app
from workbench.tui.dialogs.identity import IdentityDialog
from workbench.wire.settings import AppSettings

from .labs_support import DRIVE, open_exercise, text
from .support import run


def test_a_name_typed_in_lower_case_resumes_the_saved_progress(tmp_path):
    data = tmp_path / "data"
    first = make_app(AppSettings(paused=True, student="Alice Doe", data_dir=data))

    async def drive(pilot: Pilot) -> None:
        screen = await open_exercise(pilot, DRIVE)
        await pilot.press("a", "escape", "w", "a", "s", "d", "space", "l")
        await pilot.pause()
        assert text(screen, "#labs-objectives").startswith("[X] drove with w, a, s, d")

    run(first, drive)
    again = make_app(AppSettings(paused=True, student=" alice doe ", data_dir=data, ask_names=True))

    async def resume(pilot: Pilot) -> None:
        await pilot.press("enter")  # the names as given
        await pilot.pause()
        screen = await open_exercise(pilot, DRIVE)
        assert screen.student == again.student == "Alice Doe"
        assert text(screen, "#labs-objectives").startswith(
            "[X] drove with w, a, s, d and space: passed earlier"
        )
        await pilot.press("escape")
        await pilot.pause()
        # the message line names the student as the saved progress spells the name
        assert text(pilot.app.screen, "#message").rstrip().endswith("Alice Doe (student)")

    run(again, resume)


def test_the_last_pair_is_offered_at_start_instead_of_the_login_name(tmp_path):
    data = tmp_path / "data"
    first = make_app(AppSettings(paused=True, data_dir=data, ask_names=True))

    async def name_them(pilot: Pilot) -> None:
        dialog = pilot.app.screen
        assert isinstance(dialog, IdentityDialog)
        dialog.query_one("#student", Input).value = "Ana Ruiz"
        dialog.query_one("#partner", Input).value = "Ben Ortiz"
        await pilot.press("enter")
        await pilot.pause()
        assert (first.student, first.partner) == ("Ana Ruiz", "Ben Ortiz")

    run(first, name_them)
    again = make_app(AppSettings(paused=True, data_dir=data, ask_names=True))

    async def offered(pilot: Pilot) -> None:
        dialog = pilot.app.screen
        assert isinstance(dialog, IdentityDialog)
        assert dialog.query_one("#student", Input).value == "Ana Ruiz"
        assert dialog.query_one("#partner", Input).value == "Ben Ortiz"

    run(again, offered)


def test_a_served_student_is_never_offered_another_pair(tmp_path):
    data = tmp_path / "data"
    save_last_pair(data, "Alice Doe", "Bo Li")
    workspace = tmp_path / "ws"
    workspace.mkdir()
    served = AppSettings(
        paused=True,
        data_dir=data,
        workspace=workspace,
        student="carol",
        ask_names=True,
        student_fixed=True,
    )
    app = make_app(served)
    assert (app.student, app.partner) == ("carol", "")
    # nor when no name is given: the app's own login name, not the pair kept in the data folder
    unnamed = make_app(replace(served, student=None, ask_names=False, student_fixed=False))
    assert unnamed.student != "Alice Doe" and unnamed.partner == ""


def test_a_spare_apps_dialog_shows_the_student_it_is_given_before_or_after_its_fields(tmp_path):
    """A spare app (started ahead) learns its student while its names dialog is still being
    made, or once it is up: either way the fixed name shown is theirs, and Enter keeps it."""
    app = make_app(AppSettings(paused=True, data_dir=tmp_path, ask_names=True, student_fixed=True))

    async def body(pilot: Pilot) -> None:
        early = IdentityDialog("spare", student_fixed=True)
        early.show_student("ann")  # before it has its fields
        answers: list[object] = []
        app.push_screen(early, answers.append)
        await pilot.pause()
        assert early.query_one("#student", Input).value == "ann"
        early.show_student("ben")  # once it is up
        await pilot.pause()
        assert early.query_one("#student", Input).value == "ben"
        await pilot.press("enter")
        await pilot.pause()
        assert answers and answers[-1][0] == "ben"

    run(app, body)
