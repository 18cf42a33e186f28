"""Spare apps (``serve-ssh --spare-apps N``): apps started ahead become students' sessions with
everything that is the session's own (the name on the names dialog, the terminal's size, the
workspace the run records go to), sessions a spare does not fit get an app of their own, the
pool fills again, and the spares end with the server."""

from __future__ import annotations

import asyncio
import os
import signal
from pathlib import Path

from tests.app.support import sync
from tests.waiting import until
from workbench.files.workspace import workspace_folder

from .ssh_support import Account, Terminal, gone, lab_host, moved


def children(pid: int) -> set[int]:
    found = set()
    for entry in Path("/proc").iterdir():
        if entry.name.isdigit():
            try:
                stat = (entry / "stat").read_text()
            except OSError:
                continue
            fields = stat.rsplit(")", 1)[1].split()
            if int(fields[1]) == pid and fields[0] != "Z":
                found.add(int(entry.name))
    return found


def session_pids(host) -> dict[str, int]:
    return {s.user.name: s.app.pid for s in host.server.sessions.values() if s.app is not None}


@sync
async def test_a_spare_app_becomes_the_students_session_with_all_that_is_theirs(tmp_path, caplog):
    caplog.set_level("INFO", "workbench.ssh")
    async with lab_host(tmp_path, [Account("ann"), Account("ben")], spare_apps=2) as host:
        assert "keeps 2 students' apps started ahead" in caplog.text
        forkserver = host.server.forkserver
        assert forkserver is not None
        await until(lambda: len(children(forkserver.pid)) == 2, "two spare apps waiting", 60)
        spares = children(forkserver.pid)

        ann = await host.terminal("ann", size=(90, 30))
        screen = await ann.wait_for("Who is at this robot")
        assert "ann" in screen  # the session's name, not the spare's
        assert session_pids(host)["ann"] in spares  # a spare, not a new fork
        await ann.start_app()
        await ann.wait_until(lambda t: "^q Quit" in t.splitlines()[29], "the key bar on line 30")
        ann.send("w")
        await ann.wait_until(moved, "ann's robot moving")
        ann.send(" ")
        ann.send("\x11")  # ctrl+q: the run is recorded in ann's own workspace
        assert await ann.exit_status() == 0
        await ann.close()
        runs = workspace_folder(host.data_dir, "ann") / "runs"
        await until(lambda: any(p.is_file() for p in runs.rglob("*")), "ann's run record")
        assert not (workspace_folder(host.data_dir, "ben") / "runs").exists()

        # another terminal type than the spares were started for: an app of its own
        conn = await host.connect("ben")
        process = await conn.create_process(term_type="xterm", term_size=(80, 24), encoding=None)
        ben = Terminal(conn, process, (80, 24))
        await ben.wait_for("Who is at this robot", "ben")
        assert session_pids(host)["ben"] not in spares
        await ben.close()

        # the pool fills again once nobody has come for a moment
        await until(lambda: len(children(forkserver.pid) - {session_pids(host).get("ben")}) >= 2,
                    "two spares again", 60)  # fmt: skip
        waiting = children(forkserver.pid)
    await until(lambda: all(gone(pid) for pid in waiting), "the spares end with the server")


@sync
async def test_sessions_beyond_the_spares_are_forked_and_all_work(tmp_path):
    async with lab_host(tmp_path, [Account("ann"), Account("ben"), Account("cat")],
                        spare_apps=1) as host:  # fmt: skip
        forkserver = host.server.forkserver
        assert forkserver is not None
        await until(lambda: len(children(forkserver.pid)) == 1, "one spare app waiting", 60)
        spare = children(forkserver.pid)
        terms = await asyncio.gather(*(host.terminal(n) for n in ("ann", "ben", "cat")))
        for name, term in zip(("ann", "ben", "cat"), terms, strict=True):
            await term.wait_for("Who is at this robot", name)
        pids = session_pids(host)
        assert len(set(pids.values()) & spare) == 1 and len(set(pids.values())) == 3
        await asyncio.gather(*(t.start_app() for t in terms))
        for term in terms:
            term.send("w")
        for term in terms:
            await term.wait_until(moved, "each robot moving")
        for term in terms:
            await term.close()
        await until(lambda: all(gone(pid) for pid in pids.values()), "the apps gone")
        assert os.getpid() not in pids.values()


@sync
async def test_spares_end_when_their_fork_server_is_killed_with_forked_apps_running(tmp_path):
    """An app forked while spares wait holds none of their control sockets: a fork server
    killed outright still leaves every spare its end of file, and none is left running."""
    async with lab_host(tmp_path, [Account("ann")], spare_apps=2) as host:
        forkserver = host.server.forkserver
        assert forkserver is not None
        await until(lambda: len(children(forkserver.pid)) == 2, "two spare apps waiting", 60)
        spares = children(forkserver.pid)
        conn = await host.connect("ann")  # a 16-colour terminal: an app of its own
        process = await conn.create_process(term_type="xterm", term_size=(80, 24), encoding=None)
        ann = Terminal(conn, process, (80, 24))
        await ann.wait_for("Who is at this robot", "ann")
        app = session_pids(host)["ann"]
        assert app not in spares
        os.kill(forkserver.pid, signal.SIGKILL)
        await until(lambda: all(gone(pid) for pid in spares), "the spares ended", 30)
        assert not gone(app)  # the student's app goes on
        await ann.close()
