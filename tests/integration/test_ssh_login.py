"""Logging in to the SSH lab server over real loopback SSH: keys, passwords, the app with the
student's name, driving, resizing, and what is refused."""

from __future__ import annotations

import asyncio
import logging

import asyncssh
import pytest

from tests.app.support import sync
from workbench.door.logins import LoginPolicy

from .ssh_support import PASSWORD, Account, lab_host, moved


@sync
async def test_a_student_logs_in_with_a_key_drives_and_the_layout_follows_a_resize(tmp_path):
    async with lab_host(tmp_path, [Account("ann")]) as host:
        term = await host.terminal("ann")
        await term.wait_for("Who is at this robot?", "Student  ann", timeout=30)
        screen = await term.start_app()
        assert "VIPLE from your computer: press ? for the ssh command" in screen
        term.send("?")  # the help has the forwarding command whole
        await term.wait_for("Connect VIPLE", "VIPLE: on your computer run  ssh -N -p")
        term.send("\x1b")
        await term.wait_gone("Connect VIPLE")
        term.send("w")  # Move at Power 1
        await term.wait_until(moved, "the robot moving")
        screen = await term.wait_for("ann (student)", "driver: keys")
        assert max(len(line.rstrip()) for line in screen.splitlines()) <= 80
        term.resize(120, 40)
        await term.wait_until(
            lambda t: max(len(line.rstrip()) for line in t.splitlines()) > 100,
            "a line past column 100 at 120x40",
        )
        # taller too: the key bar moves down to the 40th line
        await term.wait_until(lambda t: "^q Quit" in t.splitlines()[39], "the key bar on line 40")
        term.send("\x11")  # ctrl+q: the app ends and so does the session, with its status
        assert await term.exit_status() == 0
        await term.close()


@sync
async def test_a_password_logs_in_and_wrong_passwords_and_unknown_users_are_refused(
    tmp_path, caplog
):
    caplog.set_level(logging.INFO, logger="workbench.ssh")
    async with lab_host(tmp_path, [Account("bo", password=PASSWORD)]) as host:
        term = await host.terminal("bo", password=PASSWORD)
        await term.start_app()
        term.send(" ")  # any key: the message line makes room for the name
        await term.wait_for("bo (student)")
        await term.close()
        with pytest.raises(asyncssh.PermissionDenied):
            await host.connect("bo", password="not-the-password")
        with pytest.raises(asyncssh.PermissionDenied):
            await host.connect("mallory", password=PASSWORD)
        log = caplog.text
        assert "login refused: bo from 127.0.0.1: wrong password" in log
        assert "login refused: mallory from 127.0.0.1: unknown user" in log
        assert "login: bo (student) from 127.0.0.1 with password" in log


@sync
async def test_repeated_failures_from_one_address_are_answered_more_slowly(tmp_path):
    policy = LoginPolicy(first_delay=0.2, max_delay=0.8)
    async with lab_host(tmp_path, [Account("cy", password=PASSWORD)], logins=policy) as host:
        times = []
        for _ in range(4):
            start = asyncio.get_running_loop().time()
            with pytest.raises(asyncssh.PermissionDenied):
                await host.connect("cy", password="wrong-password")
            times.append(asyncio.get_running_loop().time() - start)
        # no wait for the first failure, then 0.2 s doubling: 0.8 s before the fourth answer
        assert times[3] > times[0] + 0.6, times


@sync
async def test_a_client_that_prefers_chacha20_gets_aes_and_one_with_only_chacha20_is_refused(
    tmp_path,
):
    # OpenSSH offers chacha20-poly1305 first; the server takes AES only (far cheaper per packet)
    openssh_order = ["chacha20-poly1305@openssh.com", "aes128-ctr", "aes128-gcm@openssh.com"]
    async with lab_host(tmp_path, [Account("ann")]) as host:
        conn = await host.connect("ann", encryption_algs=openssh_order)
        assert conn.get_extra_info("send_cipher") == "aes128-ctr"
        assert conn.get_extra_info("send_mac") == "hmac-sha2-256-etm@openssh.com"
        conn.close()
        conn = await host.connect("ann")  # asyncssh's own order: GCM, which needs no MAC
        assert conn.get_extra_info("send_cipher").startswith("aes")
        assert "gcm" in conn.get_extra_info("send_cipher")
        conn.close()
        with pytest.raises(asyncssh.KeyExchangeFailed):
            await host.connect("ann", encryption_algs=["chacha20-poly1305@openssh.com"])
