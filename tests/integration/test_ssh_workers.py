"""The server's worker threads: session starts waiting on a course store that does not answer
(a locked table) hold no thread a login needs."""

from __future__ import annotations

import asyncio
import os
import threading

from tests.app.support import sync
from tests.waiting import until
from workbench.door.limits import SessionLimits
from workbench.labs.store.workspace_sync import SyncReport
from workbench.ssh import server as server_module

from .ssh_support import PASSWORD, Account, lab_host

#: threads of asyncio's default pool, all of which the session starts below hold
DEFAULT_POOL = min(32, (os.cpu_count() or 1) + 4)


@sync
async def test_logins_go_on_while_session_starts_wait_on_a_locked_store(tmp_path, monkeypatch):
    release = threading.Event()
    waiting: list[str] = []

    def locked_store(data_dir, db, user, workspace):
        waiting.append(user)
        release.wait(60)
        return SyncReport()

    monkeypatch.setattr(server_module, "sync_at_start", locked_store)
    starts = DEFAULT_POOL + 1
    limits = SessionLimits(per_user=starts, connections_per_user=starts)
    accounts = [Account("mallory"), Account("ann", password=PASSWORD)]
    async with lab_host(
        tmp_path, accounts, limits=limits, db="postgresql://127.0.0.1:9/course"
    ) as host:
        conns = [await host.connect("mallory") for _ in range(starts)]
        for conn in conns:
            await conn.create_process(term_type="xterm-256color", term_size=(80, 24))
        # as many as asyncio's default pool has threads (more in a pool of their own)
        await until(lambda: len(waiting) >= DEFAULT_POOL, "session starts waiting on the store")
        try:
            # the password is checked while every one of them still waits
            ann = await asyncio.wait_for(host.connect("ann", password=PASSWORD), 20)
            ann.close()
        finally:
            for conn in conns:
                conn.close()
            release.set()
