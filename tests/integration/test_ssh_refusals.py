"""What the lab server refuses, with a message the user can read: commands, subsystems but SFTP, a
session without a terminal, and sessions past the limits; idle sessions are closed."""

from __future__ import annotations

import asyncio
import os

import pytest

from tests.app.support import sync
from tests.waiting import until
from workbench.door.limits import SessionLimits

from .ssh_support import Account, lab_host


@sync
async def test_commands_file_transfer_and_sessions_without_a_terminal_are_refused(tmp_path):
    async with lab_host(tmp_path, [Account("ann")]) as host:
        conn = await host.connect("ann")
        result = await conn.run("cat /etc/passwd", check=False)
        assert result.exit_status == 1
        assert result.stdout == ""
        assert "runs the workbench only: no commands" in result.stderr

        result = await conn.run(subsystem="netconf", check=False)
        assert result.exit_status == 1
        assert "takes files by SFTP only (subsystem 'netconf' refused)" in result.stderr

        result = await conn.run(check=False)  # a shell, but no pty
        assert result.exit_status == 1
        assert "in a terminal" in result.stderr
        assert not host.server.sessions  # no app was started for any of them
        conn.close()


@sync
async def test_the_limits_give_a_message_and_a_non_zero_exit_instead_of_a_hang(tmp_path):
    accounts = [Account("ann"), Account("ben"), Account("cy")]
    limits = SessionLimits(per_user=1, total=2)
    async with lab_host(tmp_path, accounts, limits=limits) as host:
        ann = await host.terminal("ann")
        await ann.start_app()
        again = await host.terminal("ann")
        await again.wait_for("You already have 1 workbench session open")
        assert await again.exit_status() == 1

        ben = await host.terminal("ben")
        await ben.start_app()
        cy = await host.terminal("cy")
        await cy.wait_for("The lab server is full (2 sessions); try again in a few minutes.")
        assert await cy.exit_status() == 1
        assert len(host.server.sessions) == 2
        await asyncio.gather(*(t.close() for t in (ann, again, ben, cy)))


@sync
async def test_an_idle_session_is_closed_with_a_message(tmp_path):
    limits = SessionLimits(idle_timeout=2.0)
    async with lab_host(tmp_path, [Account("ann")], limits=limits) as host:
        term = await host.terminal("ann")
        # the session's app, taken as soon as it is started: on a busy machine the session can
        # be idle for 2 s before the app has drawn its first screen
        app = await until(
            lambda: next((s.app for s in host.server.sessions.values() if s.app), None),
            "the session's app",
        )
        pid = await until(lambda: app.pid, "the app's process")
        await term.wait_for("No input for 2 s: the session was closed.", timeout=30)
        assert await term.exit_status() == 1
        assert b"Your lab progress is saved; log in again to go on." in term.raw
        with pytest.raises(ProcessLookupError):
            os.kill(pid, 0)  # the app process is gone
        await term.close()
