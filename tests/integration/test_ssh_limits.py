"""What one student (or one person without an account) can spend on the lab server, attacked
over loopback with small caps: logged-in connections, places at the login filled from several
addresses, a huge terminal and a storm of window changes, an app's memory, and the server's
open files (a server run with a low limit)."""

from __future__ import annotations

import asyncio
import logging
import re
import resource
import shutil
import subprocess
import sys
import time
from pathlib import Path

import asyncssh
import pytest

from tests.app.support import sync
from workbench.door.appproc import AppEntry, AppProcess
from workbench.door.limits import SessionLimits
from workbench.door.logins import LoginPolicy

from .ssh_support import Account, Terminal, idle_socket, lab_host, make_accounts
from .test_ssh_guessing import closed_within


class Watcher(asyncssh.SSHClient):
    """Keeps what the connection ended with."""

    def __init__(self) -> None:
        self.ended: Exception | None = None

    def connection_lost(self, exc: Exception | None) -> None:
        self.ended = exc


async def refused_reason(host, name: str, **options) -> str:
    """The disconnect reason of a login the server closes at once (before or after the
    client learns it logged in)."""
    watcher = Watcher()
    try:
        conn = await host.connect(name, client_factory=lambda: watcher, **options)
    except asyncssh.DisconnectError as exc:
        return exc.reason
    await asyncio.wait_for(conn.wait_closed(), 10)
    assert isinstance(watcher.ended, asyncssh.DisconnectError), watcher.ended
    return watcher.ended.reason


@sync
async def test_a_student_s_logged_in_connections_are_capped_and_others_still_log_in(
    tmp_path, caplog
):
    caplog.set_level(logging.INFO, logger="workbench.ssh")
    limits = SessionLimits(connections_per_user=3)
    async with lab_host(tmp_path, [Account("mallory"), Account("ann")], limits=limits) as host:
        held = [await host.connect("mallory") for _ in range(3)]  # logged in, no session
        for _ in range(4):
            reason = await refused_reason(host, "mallory")
            assert "You already have 3 connections to the lab server" in reason
        assert caplog.text.count("login refused: mallory from 127.0.0.1: 3 connections") == 1
        assert host.server.user_connections["mallory"] == 3
        ann = await host.connect("ann")  # another student is not held up
        ann.close()
        held.pop().close()
        await asyncio.wait_for(_until(lambda: host.server.user_connections["mallory"] == 2), 10)
        again = await host.connect("mallory")  # a place freed is a place to log in
        for conn in (*held, again):
            conn.close()


async def _until(check) -> None:
    while not check():
        await asyncio.sleep(0.02)


@pytest.mark.skipif(shutil.which("ssh") is None, reason="no OpenSSH client (openssh-client)")
@sync
async def test_openssh_shows_the_student_why_the_login_was_closed(tmp_path):
    limits = SessionLimits(connections_per_user=1)
    async with lab_host(tmp_path, [Account("ann")], limits=limits) as host:
        held = await host.connect("ann")
        key = tmp_path / "id_ann"
        key.write_bytes(host.accounts["ann"].key.export_private_key())
        key.chmod(0o600)
        argv = [
            "ssh", "-F", "/dev/null", "-i", str(key), "-p", str(host.port), "-N",
            "-o", "StrictHostKeyChecking=no", "-o", "UserKnownHostsFile=/dev/null",
            "-o", "BatchMode=yes", "ann@127.0.0.1",
        ]  # fmt: skip
        done = await asyncio.to_thread(
            subprocess.run, argv, capture_output=True, text=True, timeout=30
        )
        assert done.returncode != 0
        assert "You already have 1 connection to the lab server" in done.stderr, done.stderr
        held.close()


@sync
async def test_idle_connections_from_several_addresses_do_not_keep_a_student_out(tmp_path, caplog):
    """The caps on connections not logged in (20 in all, 5 an address) filled from four
    addresses: once they time out, those addresses are refused for a while and cannot fill
    the places again, so a student from a fifth address logs in."""
    caplog.set_level(logging.INFO, logger="workbench.ssh")
    policy = LoginPolicy(
        max_unauthenticated=20,
        max_unauthenticated_per_address=5,
        login_timeout=1.0,
        penalty_least=3.0,
        penalty_longest=60.0,
        seed=1,
    )
    attackers = [f"127.0.0.{n}" for n in range(2, 6)]
    async with lab_host(tmp_path, [Account("ann")], logins=policy) as host:
        flood = [await idle_socket(host.port, a) for a in attackers for _ in range(5)]
        await asyncio.wait_for(_until(lambda: host.server.gate.unauthenticated.total() == 20), 10)
        assert all(await asyncio.gather(*(closed_within(r, 10) for r, _ in flood)))  # timed out
        for _, writer in flood:
            writer.close()
        again = [await idle_socket(host.port, a) for a in attackers for _ in range(5)]
        conn = await host.connect("ann", local_addr=("127.0.0.9", 0))  # after all of them
        conn.close()
        said = await asyncio.gather(*(all_it_says(r, 10) for r, _ in again))
        assert all(b"too many connections waiting to log in" in s for s in said)
        for address in attackers:
            assert f"connections from {address} refused for" in caplog.text
        for _, writer in again:
            writer.close()


@sync
async def test_a_student_gets_in_while_idle_connections_from_ten_addresses_fill_the_places(
    tmp_path, caplog
):
    """The places at the login (20, 2 an address) filled with idle connections from ten
    addresses that would not time out for two minutes: once they have sat on their places for
    the grace (1 s), a student from an eleventh address takes the place of one of them, and
    the others stay open."""
    caplog.set_level(logging.INFO, logger="workbench.ssh")
    policy = LoginPolicy(
        max_unauthenticated=20,
        max_unauthenticated_per_address=2,
        unauthenticated_grace=1.0,
        login_timeout=120.0,
    )
    attackers = [f"127.0.0.{n}" for n in range(2, 12)]
    async with lab_host(tmp_path, [Account("ann")], logins=policy) as host:
        gate = host.server.gate
        flood = [await idle_socket(host.port, a) for a in attackers for _ in range(2)]
        await asyncio.wait_for(_until(lambda: gate.unauthenticated.total() == 20), 10)
        await asyncio.sleep(policy.unauthenticated_grace)  # every place is past its grace
        reads = [asyncio.create_task(all_it_says(r, 60)) for r, _ in flood]
        ann = await host.connect("ann", local_addr=("127.0.0.20", 0))
        assert gate.unauthenticated.total() == 19  # one gave up its place; ann logged in
        done, _ = await asyncio.wait(reads, timeout=30, return_when=asyncio.FIRST_COMPLETED)
        [closed] = done
        assert b"closed this connection to make room for others" in closed.result()
        said = "to make room for one from 127.0.0.20: it held a place at the login"
        assert said in caplog.text
        assert sum(r.done() for r in reads) == 1  # the other 19 still hold their places
        ann.close()
        for read in reads:
            read.cancel()
        for _, writer in flood:
            writer.close()


async def all_it_says(reader: asyncio.StreamReader, seconds: float) -> bytes:
    """What the server sends on a connection that says nothing, until it closes it."""
    said = b""
    async with asyncio.timeout(seconds):
        while chunk := await reader.read(4096):
            said += chunk
    return said


@sync
async def test_a_refused_connection_reads_why(tmp_path):
    policy = LoginPolicy(
        max_unauthenticated=2, max_unauthenticated_per_address=2, unauthenticated_grace=60
    )
    async with lab_host(tmp_path, [Account("ann")], logins=policy) as host:
        held = [await idle_socket(host.port) for _ in range(2)]
        await asyncio.wait_for(_until(lambda: host.server.gate.unauthenticated.total() == 2), 10)
        reason = await refused_reason(host, "ann")
        assert "too many connections waiting to log in" in reason
        for _, writer in held:
            writer.close()


async def pty_session(host, name: str, size: tuple[int, int], shown: tuple[int, int]):
    """A terminal asking for ``size``, read into a screen of ``shown`` (a pyte screen of a
    huge size would be the test's own memory)."""
    conn = await host.connect(name)
    process = await conn.create_process(term_type="xterm-256color", term_size=size, encoding=None)
    return Terminal(conn, process, shown)


async def the_session(host, name: str):
    await asyncio.wait_for(
        _until(lambda: any(s.app is not None for s in host.server.live(name))), 30
    )
    return host.server.live(name)[0]


@sync
async def test_a_huge_terminal_is_clamped_and_the_app_draws(tmp_path, caplog):
    caplog.set_level(logging.INFO, logger="workbench.ssh")
    limits = SessionLimits(max_columns=300, max_rows=100)
    async with lab_host(tmp_path, [Account("ann")], limits=limits) as host:
        term = await pty_session(host, "ann", (65535, 65535), (300, 100))
        session = await the_session(host, "ann")
        assert (session.spec.width, session.spec.height) == (300, 100)
        await term.wait_for("Who is at this robot?", timeout=30)
        assert "terminal of ann from 127.0.0.1 is 65535x65535: the app is given 300x100" in (
            caplog.text
        )
        await term.close()


@sync
async def test_a_storm_of_window_changes_reaches_the_app_as_its_latest_size(tmp_path, monkeypatch):
    given: list[tuple[int, int]] = []
    resize = AppProcess.resize

    def counted(self, width: int, height: int) -> None:
        given.append((width, height))
        resize(self, width, height)

    monkeypatch.setattr(AppProcess, "resize", counted)
    async with lab_host(tmp_path, [Account("ann")], limits=SessionLimits(resize_every=1.0)) as host:
        term = await pty_session(host, "ann", (80, 24), (120, 40))
        await term.wait_for("Who is at this robot?", timeout=30)
        for n in range(300):
            huge = n % 2 == 0
            term.process.change_terminal_size(65535 if huge else 81 + n % 40, 65535 if huge else 30)
        term.process.change_terminal_size(120, 40)
        await asyncio.wait_for(_until(lambda: given and given[-1] == (120, 40)), 20)
        assert len(given) <= 3, given  # not 301: the latest size, once a second at most
        assert all(w <= 500 and h <= 200 for w, h in given), given
        await term.wait_until(lambda t: "Who is at this robot?" in t, "the dialog at 120x40")
        await term.close()


#: an app that takes memory until it has 1 GiB (under a cap, it fails before)
HOG = AppEntry(
    command=(sys.executable, "-m", "tests.integration.memory_hog"),
    main="tests.integration.memory_hog:main",
)


@pytest.mark.parametrize("fork_server", [True, False], ids=["forked", "new process"])
@sync
async def test_an_app_past_its_memory_cap_is_ended_with_a_message(tmp_path, caplog, fork_server):
    caplog.set_level(logging.INFO, logger="workbench.ssh")
    limits = SessionLimits(app_memory=256)
    async with lab_host(
        tmp_path, [Account("ann")], limits=limits, app=HOG, fork_server=fork_server
    ) as host:
        term = await pty_session(host, "ann", (80, 24), (80, 24))
        await term.wait_for("used more than its share of memory (256 MiB)", timeout=60)
        assert await term.exit_status() != 0
        assert "ann's app ended at its memory cap (256 MiB)" in caplog.text
        await term.close()


# -- the server's open files --------------------------------------------------------------------
def low_file_limit(soft: int, hard: int):
    def apply() -> None:
        resource.setrlimit(resource.RLIMIT_NOFILE, (soft, hard))

    return apply


async def key_login(port: int, account: Account) -> asyncssh.SSHClientConnection:
    return await asyncssh.connect(
        "127.0.0.1", port, username=account.name, client_keys=[account.key],
        known_hosts=None, agent_path=None, preferred_auth=["publickey"], connect_timeout=10,
    )  # fmt: skip


def test_at_its_open_file_limit_the_server_refuses_in_one_line_and_lives_on(tmp_path):
    """One student holding every connection the server's files allow (the per-user cap set
    high): the server raised its soft limit, refuses what is past it with a reason and one
    log line, and takes logins again as soon as files are free."""
    data = tmp_path / "data"
    accounts = make_accounts(data, [Account("mallory"), Account("ann")])
    argv = [
        sys.executable, "-m", "workbench", "serve-ssh", "--bind", "127.0.0.1", "--port", "0",
        "--data-dir", str(data), "--no-fork-server", "--max-connections-per-user", "1000",
    ]  # fmt: skip
    errors = tmp_path / "stderr.txt"
    with open(errors, "wb") as stderr:
        server = subprocess.Popen(
            argv, stdout=subprocess.DEVNULL, stderr=stderr, preexec_fn=low_file_limit(64, 160)
        )
    try:
        log = data / "ssh.log"
        port = wait_for_port(server, log)
        assert "160 open files (raised from 64)" in log.read_text()
        refused, held = asyncio.run(hog_and_log_in(port, accounts))
        assert "The lab server is full" in refused
        assert 60 < held < 160
        text = log.read_text()
        assert text.count("of the server's 160 open files are in use") == 1, text[-2000:]
        assert server.poll() is None  # still serving
    finally:
        server.terminate()
        server.wait(15)
    output = errors.read_text()
    assert "Traceback" not in output and "Too many open files" not in output, output[-3000:]


def wait_for_port(server: subprocess.Popen, log: Path) -> int:
    deadline = time.monotonic() + 60
    while True:
        found = re.search(
            r"serving on 127\.0\.0\.1 port (\d+)", log.read_text() if log.exists() else ""
        )
        if found:
            return int(found.group(1))
        assert server.poll() is None and time.monotonic() < deadline, "the server did not start"
        time.sleep(0.1)


async def hog_and_log_in(port: int, accounts: dict[str, Account]) -> tuple[str, int]:
    """mallory logs in until refused (a few more after that); then ann cannot, until mallory
    lets go, and then can. The first refusal's reason and how many mallory held."""
    held: list[asyncssh.SSHClientConnection] = []
    reasons: list[str] = []
    for _ in range(200):
        try:
            held.append(await key_login(port, accounts["mallory"]))
        except asyncssh.DisconnectError as exc:
            reasons.append(exc.reason)
            if len(reasons) == 5:
                break
    assert reasons, f"{len(held)} connections and not one refused"
    for conn in held:
        conn.close()
    for conn in held:
        await asyncio.wait_for(conn.wait_closed(), 10)
    ann = await key_login(port, accounts["ann"])
    ann.close()
    return reasons[0], len(held)
