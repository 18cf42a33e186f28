"""The console asks the instructor about the partner a request names before it signs (issue
37): a sign-off for the pair is the partner's too, so it is made only when the instructor says
the partner worked on it, and never for a name that is not a student of the class."""

from __future__ import annotations

from textual.widgets import Button

from tests.waiting import until
from workbench.labs.signoff.instructors import create_instructor
from workbench.labs.store.store import Store
from workbench.tui.dialogs.pair import PairDialog
from workbench.tui.screens.console_request import RequestScreen

from .console_support import EXERCISE, LAB, save_student
from .support import screen_lines, sync
from .test_console import FAST, PASS, console, queue_lines, status


async def open_and_sign(pilot, app) -> RequestScreen:
    await until(lambda: len(queue_lines(app)) == 1, "the request")
    await pilot.press("enter")
    request = app.screen
    assert isinstance(request, RequestScreen)
    await until(lambda: request.request is not None, "the saved progress")
    await pilot.click("#request-passphrase")
    await pilot.press(*PASS, "enter")
    await until(lambda: isinstance(app.screen, PairDialog), "the pair's question")
    return request


@sync
async def test_a_partner_who_is_not_in_the_class_is_never_signed_for(tmp_path):
    data = tmp_path / "data"
    create_instructor(data, "Dr Chen", PASS, kdf=FAST)
    with Store.open(data) as store:
        save_student(store, "ana")
        store.queue.request("ana", "zed", "ana", LAB, EXERCISE)
    app = console(data)
    async with app.run_test(size=(80, 24)) as pilot:
        request = await open_and_sign(pilot, app)
        dialog = app.screen
        shown = "\n".join(screen_lines(app))
        assert "zed is not a student of this class" in shown
        assert not dialog.query("#pair")  # only "ana alone" and cancel are offered
        await pilot.press("y")
        assert app.screen is dialog
        await pilot.press("n")
        await until(lambda: "signed off ana " in status(request), "the sign-off")
        assert "ana and zed" not in status(request)
    with Store.open(data) as store:
        (row,) = store.signoffs.of()
    assert (row.student, row.partner) == ("ana", "")


@sync
async def test_the_instructor_signs_for_the_student_alone_when_the_partner_did_not_help(tmp_path):
    data = tmp_path / "data"
    create_instructor(data, "Dr Chen", PASS, kdf=FAST)
    with Store.open(data) as store:
        save_student(store, "ana")
        store.progress.set_place("ben", LAB, EXERCISE)
        store.queue.request("ana", "ben", "ana", LAB, EXERCISE)
    app = console(data)
    async with app.run_test(size=(80, 24)) as pilot:
        request = await open_and_sign(pilot, app)
        assert app.screen.query_one("#pair", Button)  # ben is in the class: the pair is offered
        await pilot.press("escape")  # not yet: nothing signed
        await until(lambda: app.screen is request, "back to the request")
        assert "not signed" in status(request)
        await pilot.click("#request-passphrase")
        await pilot.press("enter")  # the passphrase is still typed in
        await until(lambda: isinstance(app.screen, PairDialog), "the question again")
        await pilot.press("n")
        await until(lambda: "signed off ana " in status(request), "the sign-off")
    with Store.open(data) as store:
        (row,) = store.signoffs.of()
    assert (row.student, row.partner) == ("ana", "")
