"""A student's laptop goes away mid-run: the app process ends and is reaped, its ports are
free again, and logging in again shows the lab progress saved before."""

from __future__ import annotations

import asyncio

from tests.app.support import sync
from tests.waiting import until
from workbench.door.ports import port_is_free

from .ssh_support import Account, gone, lab_host, open_exercise

DRIVE = "Unity simulator: Drive by wire"
KEYS_DONE = "[X] drove with w, a, s, d and space"


@sync
async def test_a_dropped_connection_ends_the_app_frees_its_ports_and_progress_survives(tmp_path):
    async with lab_host(tmp_path, [Account("ann")]) as host:
        term = await host.terminal("ann", size=(100, 30))
        await term.start_app()
        await open_exercise(term, DRIVE)
        term.send("a")  # the exercise's set-up
        await term.wait_for("set up: unity")
        term.send("\x1b")
        await term.wait_gone("esc Back")
        for key in "wasd ":
            term.send(key)
        term.send("l")
        await term.wait_for(KEYS_DONE)  # saved in the data folder's store as it passed

        session = host.server.live("ann")[0]
        pid, ports = session.app.pid, session.ports
        assert not any(port_is_free(p) for p in ports[:1])  # the app listens on its TCP port
        term.conn.abort()  # no goodbye: the laptop's lid closed
        await until(lambda: gone(pid), "the app process gone")
        await until(lambda: all(port_is_free(p) for p in ports), "the ports free")
        await until(lambda: not host.server.sessions, "the session ended")
        assert not (set(ports) & host.server.pool.in_use)

        again = await host.terminal("ann", size=(100, 30))
        await again.start_app()
        screen = await open_exercise(again, DRIVE)
        assert KEYS_DONE in screen
        assert host.server.live("ann")[0].ports == ports  # the same ports as last time
        await again.close()


@sync
async def test_stopping_the_server_ends_every_session_cleanly(tmp_path):
    async with lab_host(tmp_path, [Account("ann"), Account("ben")]) as host:
        terms = await asyncio.gather(host.terminal("ann"), host.terminal("ben"))
        await asyncio.gather(*(t.start_app() for t in terms))
        pids = [s.app.pid for s in host.server.sessions.values()]
        await host.server.close()
        for term in terms:
            assert await term.exit_status() == 1
            assert b"The lab server is stopping." in term.raw
        assert all(gone(pid) for pid in pids)
