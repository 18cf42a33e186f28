"""Session apps forked from the fork server: each in its own session and process group, with
its exit status, its errors in its log; and the server still serves the old way when the fork
server cannot start or goes away."""

from __future__ import annotations

import asyncio
import contextlib
import logging
import os
import signal
from pathlib import Path

import pytest

from tests.app.support import sync
from tests.waiting import until
from workbench.cli.ssh import WORKBENCH_APP
from workbench.door import forkserver as forkserver_module
from workbench.door.appproc import app_env
from workbench.door.forkserver import APP_NICENESS, ForkServer, ForkServerError

from .ssh_support import Account, gone, lab_host, moved


def parent_of(pid: int) -> int:
    return int(Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[1])


@sync
async def test_the_fork_server_runs_apps_with_their_settings_errors_and_exit_status(tmp_path):
    server = ForkServer(app_env(), WORKBENCH_APP.main, WORKBENCH_APP.preload)
    await server.start()
    try:
        assert server.running and server.modules > 100
        log = tmp_path / "app.log"
        bad = await server.spawn({"no_such_setting": 1}, app_env(), log)
        assert await asyncio.wait_for(bad.wait(), 20) == 2
        bad.stdin.close()
        assert "unknown setting 'no_such_setting'" in log.read_text()

        env = {**app_env(), "COLUMNS": "90", "ROWS": "30"}
        settings = {"student": "ann", "data_dir": str(tmp_path / "d"),
                    "record_dir": str(tmp_path / "runs")}  # fmt: skip
        app = await server.spawn(settings, env, log)
        assert os.getsid(app.pid) == app.pid and os.getpgid(app.pid) == app.pid
        assert parent_of(app.pid) == server.pid
        first = await asyncio.wait_for(app.stdout.readexactly(13), 20)
        assert first == b"__GANGLION__\n"  # the web driver talks on the socket given
        # the app runs below the server's priority, also where the kernel weighs each
        # session as a group (autogroup): there the group's nice value is what counts
        ours = os.getpriority(os.PRIO_PROCESS, 0)
        assert os.getpriority(os.PRIO_PROCESS, app.pid) == min(19, ours + APP_NICENESS)
        group = Path(f"/proc/{app.pid}/autogroup")
        if group.exists():  # (set again beside the app when the kernel asks to wait)
            await until(
                lambda: group.read_text().split()[-1] == str(APP_NICENESS),
                "the app's scheduling group below the server",
            )
        assert app.returncode is None
        os.killpg(app.pid, signal.SIGKILL)
        assert await asyncio.wait_for(app.wait(), 10) == -signal.SIGKILL
        app.stdin.close()
    finally:
        await server.close()
    assert not server.running
    with pytest.raises(ForkServerError):
        await server.spawn({}, app_env(), tmp_path / "app.log")


@sync
async def test_an_app_whose_server_is_gone_ends(tmp_path):
    """A server that dies without ending its apps (killed, out of memory) leaves no app
    running for ever: each sees its input end and ends."""
    server = ForkServer(app_env(), WORKBENCH_APP.main, WORKBENCH_APP.preload)
    await server.start()
    try:
        settings = {"student": "ann", "data_dir": str(tmp_path / "d"),
                    "record_dir": str(tmp_path / "runs")}  # fmt: skip
        app = await server.spawn(settings, app_env(), tmp_path / "app.log")
        assert await asyncio.wait_for(app.stdout.readexactly(13), 20) == b"__GANGLION__\n"
        app.stdin.close()  # the server's end of the app's input and output
        await until(lambda: gone(app.pid) or app.returncode is not None, "app ended")
    finally:
        with contextlib.suppress(ProcessLookupError):
            os.killpg(app.pid, signal.SIGKILL)
        await server.close()


@sync
async def test_two_forked_sessions_at_once_resize_and_end_with_ctrl_q(tmp_path, caplog):
    caplog.set_level(logging.INFO, "workbench.ssh")
    async with lab_host(tmp_path, [Account("ann"), Account("ben")]) as host:
        assert "apps are forked from a fork server" in caplog.text
        ann, ben = await asyncio.gather(host.terminal("ann"), host.terminal("ben"))
        await asyncio.gather(ann.start_app(), ben.start_app())
        apps = [s.app for s in host.server.sessions.values()]
        assert all(a.forked for a in apps) and apps[0].pid != apps[1].pid
        assert {parent_of(a.pid) for a in apps} == {host.server.forkserver.pid}
        assert all(os.getpgid(a.pid) == a.pid for a in apps)

        ann.send("w")
        await ann.wait_until(moved, "ann's robot moving")
        assert "distance 0.00 unit" in ben.text()
        ben.resize(120, 40)
        await ben.wait_until(lambda t: "^q Quit" in t.splitlines()[39], "the key bar on line 40")

        pids = {s.user.name: s.app.pid for s in host.server.sessions.values()}
        ann.send("\x11")  # ctrl+q
        assert await ann.exit_status() == 0
        await ben.close()  # a disconnect: ben's app is stopped and reaped
        await until(lambda: all(gone(pid) for pid in pids.values()), "both apps gone")
        await until(lambda: not host.server.sessions, "no sessions left")
        await ann.close()


@sync
async def test_apps_start_as_new_processes_when_the_fork_server_does_not_start(
    tmp_path, caplog, monkeypatch
):
    async def refuse(self):
        raise ForkServerError("cannot start it: test")

    monkeypatch.setattr(forkserver_module.ForkServer, "start", refuse)
    caplog.set_level(logging.INFO, "workbench.ssh")
    async with lab_host(tmp_path, [Account("ann")]) as host:
        assert "the fork server did not start (cannot start it: test)" in caplog.text
        term = await host.terminal("ann")
        await term.start_app()
        app = host.server.live("ann")[0].app
        assert not app.forked and parent_of(app.pid) == os.getpid()
        term.send("\x11")
        assert await term.exit_status() == 0
        await term.close()


@sync
async def test_sessions_go_on_when_the_fork_server_is_lost(tmp_path, caplog):
    caplog.set_level(logging.INFO, "workbench.ssh")
    async with lab_host(tmp_path, [Account("ann"), Account("ben")]) as host:
        ann = await host.terminal("ann")
        await ann.start_app()
        first = host.server.live("ann")[0].app
        assert first.forked
        os.kill(host.server.forkserver.pid, signal.SIGKILL)
        await until(lambda: not host.server.forkserver.running, "the fork server lost")

        ben = await host.terminal("ben")  # the next session starts the old way
        await ben.start_app()
        assert not host.server.live("ben")[0].app.forked
        ann.send("w")  # and the forked one still works
        await ann.wait_until(moved, "ann's robot moving")
        ann.send("\x11")
        assert await ann.exit_status() == 0  # it said it ended, though no parent tells its status
        ben.send("\x11")
        assert await ben.exit_status() == 0
        for term in (ann, ben):
            with contextlib.suppress(Exception):
                await term.close()
