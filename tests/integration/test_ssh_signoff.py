"""An instructor signs off a student's exercise at the student's SSH session: the record is
signed with the instructor's key and names the SSH student."""

from __future__ import annotations

import asyncio
import subprocess
import sys

from tests.app.support import sync
from workbench.labs.instructors import KdfParams, create_instructor
from workbench.labs.store import Store

from .ssh_support import Account, lab_host, open_exercise

PASSPHRASE = "correct horse battery"
FAST = KdfParams(n=2**10, r=8, p=1)  # cheap scrypt for tests only


def override_ticked(text: str) -> bool:
    """The sign-off dialog's override box shows its tick (what the instructor looks for before
    going on)."""
    lines = [line for line in text.splitlines() if "Override" in line]
    return any("X" in line.partition("Override")[0] for line in lines)


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
        term.send("\t")
        await asyncio.sleep(0.2)  # a person's pace between keys: focus moves first
        term.send("checked at the station")
        await term.wait_for("at the station")
        term.send("\t ")  # to the override, and tick it
        await term.wait_until(override_ticked, "the override box ticked")
        term.send("\x1b[Z\r")  # back to the note, and sign
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
