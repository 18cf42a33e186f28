"""Sessions counted per user over every server of a data folder (``door/leases.py``): a lease
per session, held by its server's lock; a server that dies leaves none counted."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import textwrap

from workbench.door.leases import FOLDER, SessionLeases


def test_the_cap_counts_every_servers_leases_and_a_released_one_frees_its_place(tmp_path):
    ssh, web = SessionLeases(tmp_path, "ssh"), SessionLeases(tmp_path, "web")
    first, held = ssh.take("ann", 2)
    assert first is not None and held == 0
    second, held = web.take("ann", 2)
    assert second is not None and held == 1
    refused, held = ssh.take("ann", 2)
    assert refused is None and held == 2
    assert web.take("bob", 2)[0] is not None  # another student's count is their own
    second.release()
    second.release()  # twice is once
    assert ssh.count("ann") == 1 and web.count("ann") == 1
    third, held = ssh.take("ann", 2)
    assert third is not None and held == 1
    first.release()
    third.release()
    assert web.count("ann") == 0
    assert sorted(p.name for p in (tmp_path / FOLDER / "ann").iterdir()) == [".lock"]


HOLDER = textwrap.dedent(
    """
    import sys, time
    from workbench.door.leases import SessionLeases
    lease, held = SessionLeases(sys.argv[1], "web").take("ann", 5)
    print(held, flush=True)
    time.sleep(600)
    """
)


def test_a_server_killed_outright_leaves_no_session_counted(tmp_path):
    """kill -9 runs no clean-up: the kernel drops the dead server's lock, so the next count
    finds its lease unheld and removes it (no phantom session, nothing to wait out)."""
    holder = subprocess.Popen(
        [sys.executable, "-c", HOLDER, str(tmp_path)], stdout=subprocess.PIPE, text=True
    )
    try:
        assert holder.stdout is not None and holder.stdout.readline().strip() == "0"
        here = SessionLeases(tmp_path, "ssh")
        assert here.count("ann") == 1  # the other server's session, alive
        refused, held = here.take("ann", 1)
        assert refused is None and held == 1
    finally:
        os.kill(holder.pid, signal.SIGKILL)
        holder.wait()
    assert here.count("ann") == 0
    assert [p.name for p in (tmp_path / FOLDER / "ann").iterdir()] == [".lock"]
    lease, held = here.take("ann", 1)
    assert lease is not None and held == 0
    lease.release()
