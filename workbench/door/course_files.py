"""The students' workspaces and the course database, when the server shares one: brought in
step at a session's start (:func:`bring_workspace`), and the uploads sent on.

A file a student puts, removes or renames over SFTP (or sends through the browser door) changes
their workspace folder on this server; with ``--db postgresql://...`` the change goes on to the
course store, so the next session finds it on whichever server it lands. Each student's changes
are sent by a :class:`~workbench.labs.store.workspace_sync.WorkspacePusher` of their own (a thread
with a store connection it gives back when idle), so a database that is slow or away never
holds the server's event loop or the transfer: what is not sent yet stays on this server's disk
and is sent again, or at the student's next session start.
"""

from __future__ import annotations

import asyncio
import logging
import os
import threading
import time
from collections.abc import Callable
from functools import partial
from pathlib import Path

from workbench.files.workspace import workspace_folder
from workbench.labs.store.store import Store
from workbench.labs.store.workspace_sync import SyncReport, WorkspacePusher, sync_at_start

from .workers import STORE, in_pool

log = logging.getLogger("workbench.ssh")

#: seconds a session's start waits for the course store to bring the student's workspace
WORKSPACE_SYNC_WAIT = 20.0


def _tell(user: str, text: str) -> None:
    """What the pusher would tell the student: on the server, a line in its log."""
    log.warning("workspace of %s: %s", user, text)


class CourseWorkspaces:
    """Sends the SFTP changes of every student to the course store ``db``."""

    def __init__(self, data_dir: str | os.PathLike, db: str) -> None:
        self.data_dir = Path(data_dir)
        self.db = db
        self._pushers: dict[str, WorkspacePusher] = {}
        self._lock = threading.Lock()

    def changed(self, user: str, relpath: str) -> None:
        """``relpath`` of ``user``'s workspace changed (a file, a folder, or a path now gone);
        returns at once (called from the transfer's thread or the event loop)."""
        self._pusher(user).committed(workspace_folder(self.data_dir, user) / relpath)

    def _pusher(self, user: str) -> WorkspacePusher:
        with self._lock:
            pusher = self._pushers.get(user)
            if pusher is None:
                pusher = self._pushers[user] = WorkspacePusher(
                    lambda: Store.open(self.data_dir, db=self.db, offline_ok=True),
                    user,
                    workspace_folder(self.data_dir, user),
                    partial(_tell, user),
                )
                pusher.start()
            return pusher

    def close(self, wait: float) -> list[str]:
        """Stop sending, after at most ``wait`` seconds for what is on its way; the files not
        sent (``user: path``), which each student's next session start sends."""
        with self._lock:
            pushers = dict(self._pushers)
            self._pushers.clear()
        deadline = time.monotonic() + wait
        left: list[str] = []
        for user, pusher in pushers.items():
            pusher.wait_idle(max(0.0, deadline - time.monotonic()))
            pusher.stop()
            left += [f"{user}: {path}" for path in pusher.waiting]
        return left

    async def close_at_stop(self, said: logging.Logger, wait: float = 5.0) -> None:
        """Stop sending as a server stops (off its event loop, at most ``wait`` seconds), and
        log the files not sent yet, which each student's next session start sends."""
        unsent = await in_pool(STORE, self.close, wait)
        if unsent:
            said.warning("stopping: %d uploaded file(s) not in the course store yet (sent at "
                         "each student's next session start): %s", len(unsent),
                         ", ".join(unsent[:10]))  # fmt: skip


async def bring_workspace(
    data_dir: Path,
    db: str,
    user: str,
    workspace: Path,
    who: str,
    sync: Callable[[Path, str, str, Path], SyncReport] = sync_at_start,
) -> None:
    """Bring ``user``'s files from the course store before their app starts (in a thread; a
    store that does not answer within :data:`WORKSPACE_SYNC_WAIT` lets the session start with
    the files this server has). ``who`` names the session in the log."""
    try:
        report = await asyncio.wait_for(
            in_pool(STORE, sync, data_dir, db, user, workspace), WORKSPACE_SYNC_WAIT
        )
    except TimeoutError:
        log.warning("%s: %s's workspace: the course store did not answer within %g s: "
                    "starting with this server's files", who, user,
                    WORKSPACE_SYNC_WAIT)  # fmt: skip
        return
    if report.fetched or report.removed or report.pushed:
        log.info(
            "%s: %s's workspace: %d file(s) brought, %d removed, %d sent",
            who, user, len(report.fetched), len(report.removed), len(report.pushed),
        )  # fmt: skip
    for problem in report.problems[:20]:
        text = "".join(c if c.isprintable() else "?" for c in problem[:300])
        log.warning("%s: %s's workspace: %s", who, user, text)
