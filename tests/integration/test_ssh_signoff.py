"""An instructor signs off a served student's exercise from their own SSH session (OpenSSH's
``ssh -tt``, as an instructor logs in): the student asks with the ready key, the request shows on
the instructor's console, the passphrase is typed only there, and the student's screen shows
the sign-off. The student's own session never offers a signing dialog."""

from __future__ import annotations

import shutil
import subprocess
import sys

import pytest

from tests.app.support import sync
from workbench.labs.signoff.instructors import KdfParams, create_instructor
from workbench.labs.store.store import Store

from .openssh_terminal import OpenSshTerminal
from .ssh_support import Account, lab_host, open_exercise

PASSPHRASE = "correct horse battery"
FAST = KdfParams(n=2**10, r=8, p=1)  # cheap scrypt for tests only


@pytest.mark.skipif(shutil.which("ssh") is None, reason="no OpenSSH client (openssh-client)")
@sync
async def test_the_instructor_signs_from_their_own_session_and_the_student_sees_it(tmp_path):
    accounts = [Account("ann"), Account("ito", role="instructor")]
    async with lab_host(tmp_path, accounts) as host:
        kept = tmp_path / "instructor" / "roster.json"  # the instructor's own copy
        create_instructor(host.data_dir, "ito", PASSPHRASE, kdf=FAST, trusted=kept)
        student = await host.terminal("ann")
        await student.start_app()
        await open_exercise(student, "Unity simulator: Drive by wire")
        # no signing in the student's session: the key bar offers none, and i opens nothing
        screen = await student.wait_for("r Ready")
        assert "Sign off" not in screen
        student.send("i")
        student.send("r")
        await student.wait_for("1st in the queue")

        key = tmp_path / "id_ito"
        key.write_bytes(host.accounts["ito"].key.export_private_key())
        key.chmod(0o600)
        instructor = OpenSshTerminal("ito", host.port, key)
        try:
            await instructor.wait_for("Sign-off queue: 1 waiting", "1. ann")
            instructor.send("\r")
            await instructor.wait_for("ann ask for sign-off", "objectives pass")
            instructor.send(PASSPHRASE)  # typed in the instructor's own terminal
            await instructor.wait_for("•" * len(PASSPHRASE))
            instructor.send("\t")
            instructor.send("checked at the console")
            await instructor.wait_for("at the console")
            instructor.send("\t")
            instructor.send(" ")  # the override, ticked
            await instructor.wait_for("[X] Override")
            instructor.send("\x13")  # ctrl+s signs
            await instructor.wait_for("signed off ann unity-simulator/drive-by-wire as ito")
            # the student's screen shows it without a key pressed
            await student.wait_for("[*] Drive by wire", "signed off by ito on", timeout=5)
        finally:
            instructor.close()
        await student.close()

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
        (record,) = store.signoffs.of()
        assert store.queue.waiting() == []
    assert (record.instructor, record.student) == ("ito", "ann")
    assert (record.lab, record.exercise) == ("unity-simulator", "drive-by-wire")
    assert record.override and record.note == "checked at the console"
