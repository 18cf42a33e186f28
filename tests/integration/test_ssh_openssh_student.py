"""A served student through OpenSSH's own client (``ssh -tt``), as students log in: the labs
offer no sign-off key at the student's terminal, and the Unity lab's TCP-port question takes
the port this session's workbench shows (each session listens on a port of its own)."""

from __future__ import annotations

import re
import shutil

import pytest

from tests.app.support import sync

from .openssh_terminal import OpenSshTerminal
from .ssh_support import Account, lab_host, open_exercise

LISTENING = re.compile(r"VIPLE tcp listening on 127\.0\.0\.1:(\d+)")


@pytest.mark.skipif(shutil.which("ssh") is None, reason="no OpenSSH client (openssh-client)")
@sync
async def test_a_student_over_openssh_has_no_sign_off_key_and_answers_with_the_port_shown(
    tmp_path,
):
    async with lab_host(tmp_path, [Account("ann")]) as host:
        key = tmp_path / "id_ann"
        key.write_bytes(host.accounts["ann"].key.export_private_key())
        key.chmod(0o600)
        student = OpenSshTerminal("ann", host.port, key)
        try:
            await student.start_app()
            # the run panel's last line comes after its distance line, maybe in a later packet
            main = await student.wait_until(
                lambda t: LISTENING.search(t) is not None, "the session's VIPLE port shown"
            )
            shown = LISTENING.search(main)
            assert shown is not None, main
            port = shown.group(1)
            assert port != "1350"  # a session's own port, not the simulator's
            screen = await open_exercise(student, "Unity simulator: Drive by wire")
            assert "r Ready" in screen and "Sign off" not in screen
            student.send("i")  # not offered, and no signing dialog opens
            student.send("\t\t")  # the pane, then the answer field
            await student.wait_for("not answered yet", "esc Back")
            student.send(port + "\r")
            student.send("\x1b[Z\x1b[Z")  # shift+tab twice: back on the exercise list
            screen = await student.wait_for("[X] question answered", "tries: tcp-port 1")
            assert "Passphrase" not in screen
        finally:
            student.close()
