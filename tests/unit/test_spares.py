"""The fork server's spare apps: which sessions may have one, handing one out (or the next when
one has ended), and replacing spares that end on their own without starting them in a loop."""

from __future__ import annotations

import json
import os
import signal
import socket
import subprocess

import pytest

from workbench.door.spares import (
    MAX_BACKOFF,
    REFILL_QUIET,
    Spare,
    SparePool,
    SpareSpec,
    SpareSpecError,
)

TEMPLATE = {"ask_names": True, "student_fixed": True, "data_dir": "/srv/lab", "student": "student",
            "tcp_port": 1, "workspace": "/srv/lab/workspaces/student"}  # fmt: skip
ENV = {"TERM": "xterm-256color", "COLUMNS": "80", "ROWS": "24", "LANG": "C.UTF-8"}
PERSONAL = frozenset({"student", "tcp_port", "workspace", "record_dir"})


def spec(count: int = 2) -> SpareSpec:
    return SpareSpec(count, "m:f", TEMPLATE, ENV, PERSONAL)


def test_a_session_fits_a_spare_when_only_its_own_settings_and_size_differ():
    mine = TEMPLATE | {"student": "ann", "tcp_port": 41001, "workspace": "/srv/lab/w/ann",
                       "record_dir": "/srv/lab/w/ann/runs/1"}  # fmt: skip
    assert spec().fits(mine, ENV | {"COLUMNS": "120", "ROWS": "40"})
    assert not spec().fits(mine | {"role": "instructor"}, ENV)  # a setting of its own
    assert not spec().fits({k: v for k, v in mine.items() if k != "ask_names"}, ENV)
    assert not spec().fits(mine, ENV | {"TERM": "vt100"})  # another terminal type
    for alike in ("screen-256color", "tmux-256color", "XTERM-256COLOR", "xterm-kitty"):
        assert spec().fits(mine, ENV | {"TERM": alike})  # draws in the same 256 colours
    for unlike in ("xterm", "linux", "dumb", "xterm-16color"):
        assert not spec().fits(mine, ENV | {"TERM": unlike})
    assert not spec().fits(mine, ENV | {"WORKBENCH_DB": "postgresql://x/y"})


@pytest.mark.parametrize(
    ("message", "problem"),
    [
        ([], "not a JSON object"),
        ({"count": 1}, "bad spares request"),
        ({"count": -1, "main": "m:f", "settings": {}, "env": {}}, "between 0 and"),
        ({"count": 10**6, "main": "m:f", "settings": {}, "env": {}}, "between 0 and"),
        ({"count": 1, "main": "m:f", "settings": [], "env": {}}, "settings are not"),
    ],
)
def test_a_spares_request_that_cannot_be_kept_says_why(message, problem):
    with pytest.raises(SpareSpecError, match=problem):
        SpareSpec.from_message(message)


def sleeper() -> subprocess.Popen:
    return subprocess.Popen(["sleep", "60"], start_new_session=True)


def test_a_session_goes_to_the_first_live_spare_with_its_request_and_descriptors():
    now = [100.0]
    pool = SparePool(spec(), lambda *_: 0, clock=lambda: now[0])
    dead, live = sleeper(), sleeper()
    dead_ours, dead_theirs = socket.socketpair(socket.AF_UNIX, socket.SOCK_SEQPACKET)
    ours, theirs = socket.socketpair(socket.AF_UNIX, socket.SOCK_SEQPACKET)
    dead_theirs.close()  # that spare ended: sending to it fails
    pool.waiting.extend([Spare(dead.pid, dead_ours), Spare(live.pid, ours)])
    limits = []
    r, w = os.pipe()
    try:
        request = {"settings": TEMPLATE | {"student": "ann"}, "env": ENV, "cwd": "/tmp",
                   "memory": 1 << 30}  # fmt: skip
        assert pool.take(request, [r, w], lambda cap, pid: limits.append((cap, pid))) == live.pid
        message, fds, _, _ = socket.recv_fds(theirs, 1 << 16, 4)
        assert json.loads(message) == {"settings": request["settings"], "env": ENV, "cwd": "/tmp"}
        assert len(fds) == 2 and limits[-1] == (1 << 30, live.pid)
        for fd in fds:
            os.close(fd)
        assert dead.wait(10) == -signal.SIGKILL  # the spare that could not take it is ended
        assert not pool.waiting
        # a session that does not fit, or no spare left: the caller forks a new app
        assert pool.take(request, [r, w], lambda *_: None) is None
        assert pool.wait_time() == pytest.approx(REFILL_QUIET)  # refilled once arrivals pause
    finally:
        for fd in (r, w):
            os.close(fd)
        live.kill()
        live.wait()
        theirs.close()


def test_spares_that_end_on_their_own_are_replaced_later_and_later():
    now = [0.0]
    pool = SparePool(spec(count=1), lambda *_: 0, clock=lambda: now[0])
    pauses = []
    for pid in range(1000, 1010):
        ours, theirs = socket.socketpair(socket.AF_UNIX, socket.SOCK_SEQPACKET)
        theirs.close()
        pool.waiting.append(Spare(pid, ours))
        pool._refill_at = None
        assert pool.ended(pid)
        pauses.append(pool.wait_time())
    assert pauses[:4] == [REFILL_QUIET, 2 * REFILL_QUIET, 4 * REFILL_QUIET, 8 * REFILL_QUIET]
    assert max(pauses) == MAX_BACKOFF
    assert not pool.ended(4242)  # not a spare: the fork server reports it as any app's end
