"""An instructor signs off a student's exercise at the student's SSH session: the record is
signed with the instructor's key and names the SSH student."""

from __future__ import annotations

import subprocess
import sys

from tests.app.support import sync
from workbench.labs.instructors import KdfParams, create_instructor
from workbench.labs.store import Store

from .ssh_support import Account, Terminal, lab_host, open_exercise

PASSPHRASE = "correct horse battery"
FAST = KdfParams(n=2**10, r=8, p=1)  # cheap scrypt for tests only


def click(term: Terminal, text: str, after: int = 1) -> None:
    """Click the left button ``after`` cells into the first place ``text`` is shown."""
    for y, line in enumerate(term.screen.display):
        x = line.find(text)
        if x >= 0:
            at = f"{x + after + 1};{y + 1}"  # the terminal counts from 1
            term.send(f"\x1b[<0;{at}M\x1b[<0;{at}m")  # press and release (SGR mouse)
            return
    raise AssertionError(f"{text!r} not on the screen:\n{term.text()}")


@sync
async def test_an_instructor_signs_off_an_exercise_from_the_students_session(tmp_path):
    accounts = [Account("ann"), Account("ito", role="instructor")]
    async with lab_host(tmp_path, accounts) as host:
        kept = tmp_path / "instructor" / "roster.json"  # the instructor's own copy
        create_instructor(host.data_dir, "ito", PASSPHRASE, kdf=FAST, trusted=kept)
        term = await host.terminal("ann", size=(100, 30))
        await term.start_app()
        await open_exercise(term, "Unity simulator: Drive by wire")
        term.send("i")
        await term.wait_for("Sign off unity-simulator/drive-by-wire", "an override is needed")
        term.send(PASSPHRASE)  # the passphrase field has the focus (one instructor)
        await term.wait_for("•" * len(PASSPHRASE))
        # the mouse, not Tab: where a click lands does not depend on how soon the app has
        # moved the focus, however busy the machine
        click(term, "Note ", after=len("Note         "))
        term.send("checked at the station")
        await term.wait_for("at the station")
        click(term, "[ ] Override")
        await term.wait_for("[X] Override")
        click(term, "Sign off    Cancel")
        await term.wait_for("Signed off by ito (override).")
        await term.close()

    command = ["signoff", "verify", "--data-dir", str(host.data_dir), "--roster", str(kept)]
    verify = subprocess.run(
        [sys.executable, "-m", "workbench", *command],
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert verify.returncode == 0, verify.stdout + verify.stderr
    assert "all 1 record(s) verify" in verify.stdout
    with Store.open(host.data_dir, create=False) as store:
        (record,) = store.signoffs()
    assert (record.instructor, record.student) == ("ito", "ann")
    assert (record.lab, record.exercise) == ("unity-simulator", "drive-by-wire")
    assert record.override and record.note == "checked at the station"
