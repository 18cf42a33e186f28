"""A served app's error output: read by the server as it comes, so a flood of it never stalls
the app; its log stays within its cap (rotated once) and keeps the last lines; a user's old
logs make room for a new session's."""

from __future__ import annotations

import logging
import os
import sys

import pytest

from tests.app.support import sync
from workbench.door.appproc import AppEntry
from workbench.door.limits import SessionLimits

from .error_flood import LAST, LINES
from .ssh_support import Account, lab_host
from .test_ssh_limits import pty_session

#: an app that writes about 8 MB of lines to its error output, then ends
FLOOD = AppEntry(
    command=(sys.executable, "-m", "tests.integration.error_flood"),
    main="tests.integration.error_flood:main",
)


@pytest.mark.parametrize("fork_server", [True, False], ids=["forked", "new process"])
@sync
async def test_a_flood_of_error_output_neither_stalls_the_app_nor_passes_the_logs_cap(
    tmp_path, caplog, fork_server
):
    caplog.set_level(logging.INFO, logger="workbench.ssh")
    cap = 200_000
    limits = SessionLimits(app_log=cap, user_logs=1_000_000)
    logs = tmp_path / "data" / "logs" / "ann"
    logs.mkdir(parents=True)
    for n in range(4):  # earlier sessions' logs: 1.2 MB (300 kB each)
        old = logs / f"2020010{n}-000000-{n}.log"
        old.write_bytes(b"an earlier session's errors\n" * 10_714)
        os.utime(old, (1_600_000_000 + n, 1_600_000_000 + n))
    async with lab_host(
        tmp_path, [Account("ann")], limits=limits, app=FLOOD, fork_server=fork_server
    ) as host:
        term = await pty_session(host, "ann", (80, 24), (80, 24))
        # the app ends by itself only if its error output was read all along
        assert await term.exit_status(timeout=60) == 0
        await term.close()
    names = sorted(p.name for p in logs.iterdir())
    # the two oldest made room for this session's two logs (at most 2 x 200 kB)
    assert names[:2] == ["20200102-000000-2.log", "20200103-000000-3.log"]
    assert "removed ann's 2 oldest app logs (600 kB) to keep their logs within 1 MB" in caplog.text
    (current,) = [logs / n for n in names[2:] if n.endswith(".log")]
    rotated = current.with_name(current.name + ".1")
    assert current.stat().st_size <= cap and rotated.stat().st_size <= cap
    text = current.read_text()
    assert text.endswith(f"flood line {LINES - 1:06d} " + "x" * 80 + "\n" + LAST + "\n")
    assert sum(p.stat().st_size for p in logs.iterdir()) <= 1_000_000


@sync
async def test_an_app_log_that_cannot_be_written_leaves_its_last_lines_in_the_servers_log(
    tmp_path, caplog
):
    caplog.set_level(logging.INFO, logger="workbench.ssh")
    logs = tmp_path / "data" / "logs"
    logs.mkdir(parents=True)
    (logs / "ann").write_text("a file where ann's logs folder should be")
    async with lab_host(tmp_path, [Account("ann")], app=FLOOD) as host:
        term = await pty_session(host, "ann", (80, 24), (80, 24))
        assert await term.exit_status(timeout=60) == 0  # the app was not held up either
        await term.close()
    (report,) = [r.getMessage() for r in caplog.records if "'s app log " in r.getMessage()]
    assert "could not be written (File exists)" in report
    assert f"{LINES + 1} lines of the app's error output not written" in report
    assert report.endswith(f"flood line {LINES - 1:06d} " + "x" * 80 + "\n  " + LAST)
