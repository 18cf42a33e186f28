"""Asking for sign-off from the labs screen: the ready key queues the exercise, the screen
follows the request (its place, a decline's note, the sign-off made at the instructor's
console), and a served student's app offers no signing dialog."""

from __future__ import annotations

from textual.widgets import Static

from tests.waiting import until
from workbench.files.workspace import workspace_folder
from workbench.labs.signoff.instructors import KdfParams, create_instructor
from workbench.labs.signoff.signing import sign_off
from workbench.labs.signoff.signoff_record import Evidence, RecordFields
from workbench.labs.store.store import Store
from workbench.tui.app import make_app
from workbench.tui.dialogs.signoff import SignoffModal
from workbench.wire.settings import AppSettings

from .console_support import EXERCISE, LAB, progress
from .labs_support import open_exercise, text
from .support import sync

FAST = KdfParams(n=2**10, r=8, p=1)  # cheap scrypt for tests only
PASS = "correct horse battery"


def served_app(data):
    workspace = workspace_folder(data, "ana")
    settings = AppSettings(
        paused=True, workspace=workspace, data_dir=data, student="ana", student_fixed=True
    )
    return make_app(settings)


def status(screen) -> str:
    return str(screen.query_one("#labs-signoff", Static).render())


@sync
async def test_a_served_student_asks_with_r_and_sees_the_queue_and_the_sign_off(tmp_path):
    data = tmp_path / "data"
    create_instructor(data, "Dr Chen", PASS, kdf=FAST)
    with Store.open(data) as other:
        other.queue.request("cat", "", "cat", LAB, "wall-following")
    app = served_app(data)
    async with app.run_test(size=(80, 24)) as pilot:
        screen = await open_exercise(pilot, f"{LAB}/{EXERCISE}")
        # the instructor's sign-off dialog is not offered here
        await pilot.press("i")
        assert not isinstance(app.screen, SignoffModal)
        await pilot.press("r")
        await until(lambda: "2nd in the queue" in status(screen), "the place")
        with Store.open(data) as console:
            entry = next(e for e in console.queue.waiting() if e.student == "ana")
            console.queue.decline(entry.id, "Dr Chen", "drive it once more")
        await until(lambda: "drive it once more" in status(screen), "the decline")
        assert "declined by Dr Chen" in status(screen)
        await pilot.press("r")
        await until(lambda: "in the queue" in status(screen), "asked again")
        evidence = Evidence.of_progress(progress())
        with Store.open(data) as console:  # a sign-off made elsewhere, as at the console
            fields = RecordFields("ana", LAB, EXERCISE, "ana", "", evidence, True)
            sign_off(console, "Dr Chen", PASS, fields)
        await until(lambda: "signed off by Dr Chen" in text(screen, "#labs-title"),
                    "the sign-off on the student's screen")  # fmt: skip
        assert "Drive by wire" in text(screen, "#labs-title")


@sync
async def test_at_a_workbench_of_ones_own_the_dialog_stays(tmp_path):
    data = tmp_path / "data"
    create_instructor(data, "Dr Chen", PASS, kdf=FAST)
    app = make_app(AppSettings(paused=True, student="ana", data_dir=data))
    async with app.run_test(size=(80, 24)) as pilot:
        await open_exercise(pilot, f"{LAB}/{EXERCISE}")
        await pilot.press("i")
        assert isinstance(app.screen, SignoffModal)


def offered(app) -> tuple[str, list[str]]:
    """The key bar's row and the command palette's titles on the screen shown."""
    from workbench.tui.commands import WorkbenchCommands

    from .support import screen_lines

    titles = [title for title, _help, _run in WorkbenchCommands(app.screen)._commands()]
    return screen_lines(app)[-1], titles


@sync
async def test_a_served_student_is_not_offered_the_sign_off_key(tmp_path):
    data = tmp_path / "data"
    create_instructor(data, "Dr Chen", PASS, kdf=FAST)
    app = served_app(data)
    async with app.run_test(size=(80, 24)) as pilot:
        await open_exercise(pilot, f"{LAB}/{EXERCISE}")
        bar, titles = offered(app)
        assert "Ready" in bar and "Sign off" not in bar
        assert "Labs: ready for sign-off" in titles
        assert "Labs: instructor sign-off" not in titles
    app = make_app(AppSettings(paused=True, student="ana", data_dir=data))
    async with app.run_test(size=(80, 24)) as pilot:  # at a workbench of one's own it is
        await open_exercise(pilot, f"{LAB}/{EXERCISE}")
        bar, titles = offered(app)
        assert "i Sign off" in bar and "Labs: instructor sign-off" in titles
