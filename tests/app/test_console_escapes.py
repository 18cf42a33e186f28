"""Names and evidence holding terminal escapes reach the instructor's console as text, never
as escapes: the window's title and the clipboard stay the instructor's own (issue 37)."""

from __future__ import annotations

import json

from tests.waiting import until
from workbench.labs.model import load_labs
from workbench.labs.signoff.instructors import create_instructor
from workbench.labs.store.store import Store
from workbench.tui.console_app import ConsoleApp
from workbench.tui.screens.console_request import RequestScreen

from .console_support import EXERCISE, LAB, progress
from .support import emulated_terminal, sync, terminal_output
from .test_console import FAST, PASS, status

#: a maze name as a YAML file could give it before names were checked: set the window title,
#: write the clipboard (OSC 52), a CSI in its 8-bit form
TITLE = "\x1b]0;PWNED\x1b\\"
CLIPBOARD = "\x1b]52;c;cm0gLXJmIH4=\x07"
HOSTILE = f"Hall{TITLE} maze{CLIPBOARD}\x9b2J"


def save_hostile(store: Store, student: str) -> None:
    saved = json.loads(progress().to_json())
    for objective in saved["objectives"]:
        objective["evidence"]["maze"] = HOSTILE
        objective["evidence"]["driver"] = f"keys{TITLE}"
        objective["reason"] = f"done{CLIPBOARD}"
    store.progress.set_place(student, LAB, EXERCISE)
    store.progress.save(student, LAB, EXERCISE, saved)


def assert_harmless(app) -> None:
    sent = terminal_output(app)
    for escape in ("\x1b]", "\x07", "\x9b", "\x1b\\"):
        assert escape not in sent, f"{escape!r} reached the terminal"
    terminal = emulated_terminal(app)
    assert "PWNED" not in terminal.title


@sync
async def test_hostile_evidence_reaches_the_console_as_text(tmp_path):
    data = tmp_path / "data"
    create_instructor(data, "Dr Chen", PASS, kdf=FAST)
    with Store.open(data) as store:
        save_hostile(store, "ana")
        store.queue.request("ana", "", f"ana{TITLE}", LAB, EXERCISE)
    app = ConsoleApp(Store.open(data), load_labs())
    async with app.run_test(size=(80, 24)) as pilot:
        await until(lambda: "ana" in "".join(emulated_terminal(app).display), "the class")
        assert_harmless(app)
        await pilot.press("enter")
        request = app.screen
        assert isinstance(request, RequestScreen)
        await until(lambda: request.request is not None, "the saved progress")
        await pilot.pause()
        assert_harmless(app)
        shown = "\n".join(emulated_terminal(app).display)
        # the escapes are there to read, written out
        assert "\\x1b]0;PWNED" in shown
        # and such evidence cannot be signed (the workbench never saves it): the console
        # says why, with the place, and nothing raw
        await pilot.click("#request-passphrase")
        await pilot.press(*PASS, "enter")
        await until(lambda: "cannot be signed" in status(request), "the refusal")
        assert "objectives[0].reason holds an escape character" in status(request)
        assert_harmless(app)
