"""The SSH server's small parts: password hashes, the port pool, web-driver packets, the
forwarding rules, session limits and the slow-down of failed logins."""

from __future__ import annotations

import asyncio
import json
import os
import socket
import subprocess
import sys
from pathlib import Path

import pytest

from tests.waiting import wait_until
from workbench.door.appproc import AppProcess, AppSpec, forward_hint
from workbench.door.forkserver import APP_NICENESS
from workbench.door.limits import SessionLimits, describe_duration
from workbench.door.passwords import (
    PasswordError,
    check_password,
    hash_password,
    parse_hash,
    verify_password,
)
from workbench.door.ports import PoolExhausted, PortPool, parse_range, port_is_free
from workbench.ssh.forwarding import local_forward_refusal, remote_forward_refusal
from workbench.wire import packets
from workbench.wire.settings import AppSettings


# -- passwords ------------------------------------------------------------------------------
def test_a_password_hash_describes_itself_and_checks_the_password():
    hashed = hash_password("lab password 1")
    scheme, n, r, p, salt, digest = hashed.split("$")
    assert (scheme, n, r, p) == ("scrypt", "16384", "8", "1")
    assert len(salt) >= 16 and len(digest) >= 32
    assert verify_password("lab password 1", hashed)
    assert not verify_password("lab password 2", hashed)
    assert hash_password("lab password 1") != hashed  # a new salt each time
    cheap = hash_password("lab password 1", n=2**10, r=4)
    assert parse_hash(cheap)[:3] == (1024, 4, 1) and verify_password("lab password 1", cheap)


def test_short_passwords_and_broken_hashes_are_refused():
    with pytest.raises(PasswordError, match="at least 8"):
        check_password("short")
    with pytest.raises(PasswordError, match="control characters"):
        check_password("tab\there!!")
    for bad in (
        "plain",
        "bcrypt$1$2$3$4$5",
        "scrypt$1000$8$1$c2FsdHNhbHQ$aGFzaGhhc2hoYXNoaGFzaA",
        "scrypt$x$8$1$a$b",
        "scrypt$16384$8$1$$",
    ):
        with pytest.raises(PasswordError):
            parse_hash(bad)


# -- ports --------------------------------------------------------------------------------
def test_the_pool_hands_out_free_ports_and_prefers_a_users_last_ones():
    busy = {41001}
    pool = PortPool(41000, 41009, is_free=lambda p: p not in busy)
    ann = pool.allocate("ann")
    assert ann == (41000, 41002)  # 41001 is held by something else
    ben = pool.allocate("ben")
    assert not set(ann) & set(ben)
    pool.release(ann)
    pool.allocate("cy")  # takes the next free ports, not ann's
    assert pool.allocate("ann") == ann  # ann reconnects: the same ports again
    pool.release(ann)
    busy.add(41000)
    assert pool.allocate("ann") != ann  # one of them is taken meanwhile: other ports
    assert pool.allocate("dee", owned={41000})  # a port the user's own forward holds is free


def test_the_pool_says_when_it_is_exhausted_and_checks_real_ports():
    pool = PortPool(41000, 41003, is_free=lambda p: True)
    pool.allocate("a")
    pool.allocate("b")
    with pytest.raises(PoolExhausted, match="no 2 free ports left in 41000-41003"):
        pool.allocate("c")
    with socket.socket() as sock:
        sock.bind(("127.0.0.1", 0))
        sock.listen()
        assert not port_is_free(sock.getsockname()[1])
    assert parse_range("41000-41999") == (41000, 41999)
    for bad in ("41000", "80-90", "5-x", "42000-41000"):
        with pytest.raises(ValueError):
            parse_range(bad)


# -- packets ------------------------------------------------------------------------------
def test_packets_are_framed_with_a_type_and_a_big_endian_length():
    assert packets.data(b"hi") == b"D\x00\x00\x00\x02hi"
    resize = packets.resize(120, 40)
    assert resize[:1] == b"M" and int.from_bytes(resize[1:5], "big") == len(resize) - 5
    assert json.loads(resize[5:]) == {"type": "resize", "width": 120, "height": 40}
    assert json.loads(packets.quit_message()[5:]) == {"type": "quit"}


def test_the_reader_splits_any_chunks_and_keeps_what_came_before_the_start():
    stream = (
        b"a warning\n"
        + packets.GANGLION
        + packets.data("é\x1b[2J".encode())
        + packets.meta({"type": "exit"})
    )
    for size in (1, 3, 7, len(stream)):
        reader = packets.PacketReader()
        got = []
        for at in range(0, len(stream), size):
            got += reader.feed(stream[at : at + size])
        assert got == [(b"D", "é\x1b[2J".encode()), (b"M", b'{"type":"exit"}')]
        assert reader.preamble == b"a warning\n" and reader.pending == 0
    with pytest.raises(packets.PacketError):
        packets.PacketReader().feed(packets.GANGLION + b"X\x00\x00\x00\x00")


def test_packets_read_one_whole_packet_at_a_time_come_out_the_same():
    """The server's keys come one packet a read, most of the time; a read may also end inside
    one, or hold the end of one and the whole of the next."""
    reader = packets.PacketReader(marked=False)
    key, frame = packets.data(b"w"), packets.data(b"\x1b[2J" * 10)
    assert reader.feed(key) == [(b"D", b"w")]
    assert reader.feed(bytearray(key)) == [(b"D", b"w")]
    assert reader.feed(frame[:7]) == [] and reader.feed(frame[7:] + key) == [
        (b"D", b"\x1b[2J" * 10),
        (b"D", b"w"),
    ]
    assert reader.feed(packets.resize(80, 24)) == [
        (b"M", b'{"type":"resize","width":80,"height":24}')
    ]
    assert all(type(k) is bytes and type(p) is bytes for k, p in reader.feed(bytearray(key)))
    assert reader.pending == 0
    with pytest.raises(packets.PacketError):
        reader.feed(b"X\x00\x00\x00\x00")


def test_the_app_is_started_with_the_users_name_ports_and_terminal():
    spec = AppSpec(
        "ann", "student", 41000, 41001, "hint", "/d", "/d/w/ann/runs/1", "/d/w/ann",
        100, 30, "xterm",
    )  # fmt: skip
    settings = spec.settings()
    assert settings.workspace == Path("/d/w/ann")  # the student's files only
    assert (settings.student, settings.role) == ("ann", "student")
    assert settings.student_fixed and settings.ask_names  # the login's name; the partner asked
    assert settings.tcp_port == 41000 and settings.ws_url == "ws://127.0.0.1:41001/"
    assert not settings.ws_at_start  # no WebSocket attempts until the student asks
    # a new process gets them as one JSON argument, a forked app as the same JSON object
    argv = spec.argv(("workbench-app",))
    assert argv[0] == "workbench-app" and len(argv) == 2
    assert AppSettings.from_json(json.loads(argv[1])) == settings
    env = spec.env({"SSH_CONNECTION": "x", "PATH": "/bin", "TEXTUAL_DEBUG": "1"})
    assert env["TEXTUAL_DRIVER"] == "workbench.tui.serving.terminal_driver:ServedTerminalDriver"
    assert (env["COLUMNS"], env["ROWS"], env["TERM"]) == ("100", "30", "xterm")
    assert "SSH_CONNECTION" not in env and "TEXTUAL_DEBUG" not in env and env["PATH"] == "/bin"
    hint = forward_hint("ann", "lab.example", 2222, 41000, 41001)
    assert hint == (
        "VIPLE: on your computer run  ssh -N -p 2222 -L 1350:localhost:41000 "
        "-R 41001:localhost:8124 ann@lab.example  then VIPLE uses localhost:1350"
    )
    assert "-p " not in forward_hint("ann", "lab.example", 22, 41000, 41001)


def test_the_screen_output_of_one_read_reaches_the_client_in_one_write(tmp_path):
    """A frame the app wrote as several packets (begin-update, the frame, end-update) goes to
    the client's channel as one write, in order; a meta packet between splits it."""
    frame = packets.data(b"\x1b[?2026h") + packets.data(b"\x1b[3;5Hw ") + packets.data(b"<")
    tail = packets.meta({"type": "exit"}) + packets.data(b"bye")
    script = (
        "import os, sys; os.write(1, sys.argv[1].encode('latin-1') + bytes.fromhex(sys.argv[2]))"
    )
    argv = [sys.executable, "-c", script, packets.GANGLION.decode(), (frame + tail).hex()]
    writes: list[bytes] = []

    async def go() -> int:
        app = AppProcess(argv, {}, tmp_path / "app.log", writes.append)
        await app.start()
        return await app.wait()

    assert asyncio.run(go()) == 0
    assert writes == [b"\x1b[?2026h\x1b[3;5Hw <", b"bye"]


def test_an_app_started_as_a_new_process_runs_below_the_server_as_a_forked_one_does(tmp_path):
    """Without the fork server (``--no-fork-server``, or once it is lost) an app still runs ten
    nice steps below the server, its own session's group too where the kernel weighs sessions
    as groups (autogroup)."""
    argv = [sys.executable, "-c", "import sys; sys.stdin.buffer.read()"]

    async def go() -> tuple[int, str | None]:
        app = AppProcess(argv, {}, tmp_path / "app.log", lambda data: None)
        await app.start()
        assert app.pid is not None and not app.forked
        niceness = os.getpriority(os.PRIO_PROCESS, app.pid)
        group = Path(f"/proc/{app.pid}/autogroup")
        grouped = None
        if group.exists():  # the group's nice value is set just after the app starts
            deadline = asyncio.get_running_loop().time() + 10
            while (grouped := group.read_text().split()[-1]) != str(APP_NICENESS):
                if asyncio.get_running_loop().time() > deadline:
                    break
                await asyncio.sleep(0.01)
        app.process.stdin.close()
        assert await app.wait() == 0
        return niceness, grouped

    niceness, grouped = asyncio.run(go())
    assert niceness == min(19, os.getpriority(os.PRIO_PROCESS, 0) + APP_NICENESS)
    assert grouped in (None, str(APP_NICENESS))


# -- forwarding, limits, failed logins ----------------------------------------------------
def test_forwards_reach_only_the_users_own_session_ports_on_loopback():
    own = {41000, 41004}
    for host in ("localhost", "127.0.0.1", "::1", "LOCALHOST"):
        assert local_forward_refusal(host, 41000, own) is None
    assert "not the VIPLE port" in local_forward_refusal("localhost", 41002, own)
    assert "not this server's loopback" in local_forward_refusal("10.0.0.5", 41000, own)
    assert "not this server's loopback" in local_forward_refusal("example.com", 41000, own)
    assert "no workbench session" in local_forward_refusal("localhost", 41000, set())
    assert remote_forward_refusal("localhost", 41001, {41001}) is None
    assert remote_forward_refusal("127.0.0.1", 41001, {41001}) is None
    assert "only 127.0.0.1" in remote_forward_refusal("", 41001, {41001})
    assert "only 127.0.0.1" in remote_forward_refusal("0.0.0.0", 41001, {41001})
    assert "not the WebSocket port" in remote_forward_refusal("localhost", 22, {41001})


def test_limits_say_why_a_session_is_refused():
    limits = SessionLimits(per_user=2, total=60)
    assert limits.refusal(1, 59) is None
    assert limits.refusal(0, 60) == (
        "The lab server is full (60 sessions); try again in a few minutes."
    )
    assert "You already have 2 workbench sessions open" in limits.refusal(2, 3)
    assert describe_duration(7200) == "2 h" and describe_duration(90) == "90 s"
    assert describe_duration(120) == "2 min"


def test_a_group_niceness_the_kernel_asks_to_wait_for_is_set_a_moment_later(tmp_path, monkeypatch):
    """An unprivileged server may change one scheduling group's niceness every 0.1 s; a class
    logging in at once asks for more, and each app's group is set all the same, a moment
    later, while the app goes on starting."""
    from workbench.door import forkserver

    written = tmp_path / "autogroup"
    refusals = [BlockingIOError(11, "Resource temporarily unavailable")] * 3

    def fake_open(path: str, mode: str = "r"):
        assert path.endswith("/autogroup") and mode == "w"
        if refusals:
            raise refusals.pop()
        return open(written, mode)

    monkeypatch.setattr(forkserver, "open", fake_open, raising=False)
    app = subprocess.Popen([sys.executable, "-c", "import sys; sys.stdin.read()"],
                           stdin=subprocess.PIPE)  # fmt: skip
    try:
        forkserver.lower_priority(APP_NICENESS, app.pid)
        wait_until(lambda: written.exists() and written.read_text() == str(APP_NICENESS),
                   "the group's niceness set once the kernel lets it")  # fmt: skip
    finally:
        app.communicate(b"")
    assert not refusals
