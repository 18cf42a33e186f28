"""Password guessing and connection floods against the lab server, over real loopback SSH:
guesses stay slow whatever else logs in, an account locks its passwords (not its keys), idle
connections that never log in are capped and timed out, and refused forwarding is logged."""

from __future__ import annotations

import asyncio
import logging
import shutil
import subprocess
import time

import asyncssh
import pytest

from tests.app.support import sync
from tests.waiting import until
from workbench.door.logins import LoginPolicy

from .ssh_support import PASSWORD, Account, idle_socket, lab_host

FAST = {"first_delay": 0.2, "max_delay": 0.8}


async def refused_after(host, name: str, password: str, **kw) -> float:
    start = time.monotonic()
    with pytest.raises(asyncssh.PermissionDenied):
        await host.connect(name, password=password, key=False, **kw)
    return time.monotonic() - start


@sync
async def test_the_guesser_s_own_logins_between_guesses_do_not_speed_the_guessing_up(
    tmp_path, caplog
):
    caplog.set_level(logging.INFO, logger="workbench.ssh")
    accounts = [Account("mallory"), Account("rivera", role="instructor", password=PASSWORD)]
    policy = LoginPolicy(**FAST, lock_after=50)
    async with lab_host(tmp_path, accounts, logins=policy, fork_server=False) as host:
        guard = host.server.guard
        delays: list[float] = []  # the wait the server put before each password check
        delay = guard.delay
        guard.delay = lambda *who: delays.append(delay(*who)) or delays[-1]  # type: ignore[method-assign]
        times = []
        for _ in range(5):
            times.append(await refused_after(host, "rivera", "guess-guess"))
            own = await host.connect("mallory")  # a key login that succeeds, from the same address
            own.close()
        assert delays == pytest.approx([0, 0.2, 0.4, 0.8, 0.8])
        # and each refusal came no sooner than its wait (a busy machine only adds to it)
        assert all(t >= d for t, d in zip(times, delays, strict=True)), (times, delays)
        assert host.server.guard.account_failures("rivera") == 5
        assert caplog.text.count("login refused: rivera from 127.0.0.1: wrong password") == 5


@sync
async def test_parallel_guesses_at_one_account_wait_their_turn(tmp_path):
    accounts = [Account("rivera", role="instructor", password=PASSWORD)]
    policy = LoginPolicy(first_delay=0.2, max_delay=0.2, lock_after=50, address_allowance=50)
    async with lab_host(tmp_path, accounts, logins=policy, fork_server=False) as host:
        await refused_after(host, "rivera", "first-guess")
        start = time.monotonic()
        results = await asyncio.gather(
            *(refused_after(host, "rivera", f"guess-{n}") for n in range(4)),
        )
        # four guesses in parallel still cost a delay each, one after another
        assert time.monotonic() - start >= 0.8, results


@sync
async def test_too_many_wrong_passwords_lock_the_account_s_passwords_but_not_its_keys(
    tmp_path, caplog
):
    caplog.set_level(logging.INFO, logger="workbench.ssh")
    accounts = [Account("rivera", role="instructor", password=PASSWORD)]
    accounts[0].key = asyncssh.generate_private_key("ssh-ed25519")
    policy = LoginPolicy(first_delay=0.01, max_delay=0.02, lock_after=3, lock_for=60)
    async with lab_host(tmp_path, accounts, logins=policy, fork_server=False) as host:
        for n in range(3):
            await refused_after(host, "rivera", f"guess-{n}")
        assert "passwords of rivera locked for 1 min after 3 failures (keys still work)" in (
            caplog.text
        )
        await refused_after(host, "rivera", PASSWORD)  # the right password, while locked
        assert "login refused: rivera from 127.0.0.1: passwords locked for another" in caplog.text
        conn = await host.connect("rivera")  # by key
        conn.close()
        assert "login: rivera (instructor) from 127.0.0.1 with key" in caplog.text


async def closed_within(reader: asyncio.StreamReader, seconds: float) -> bool:
    """Whether the server closes the connection within ``seconds`` (reading its banner)."""
    try:
        async with asyncio.timeout(seconds):
            while await reader.read(4096):
                pass
        return True
    except (TimeoutError, ConnectionError):
        return False


@sync
async def test_idle_connections_that_never_log_in_are_capped_and_a_real_login_still_gets_in(
    tmp_path, caplog
):
    caplog.set_level(logging.INFO, logger="workbench.ssh")
    policy = LoginPolicy(max_unauthenticated=40, max_unauthenticated_per_address=10)
    async with lab_host(tmp_path, [Account("ann")], logins=policy, fork_server=False) as host:
        flood = [await idle_socket(host.port) for _ in range(300)]
        closed = await asyncio.gather(*(closed_within(r, 1.0) for r, _ in flood))
        assert closed.count(False) == 10  # held: the first ten, not yet timed out
        # the flood's address is full, another address still gets in
        conn = await host.connect("ann", local_addr=("127.0.0.2", 0))
        conn.close()
        assert "connection from 127.0.0.1 closed: 10 connections from this address" in caplog.text
        assert "more like it not logged" not in caplog.text  # one line, not 290
        for _, writer in flood:
            writer.close()


@sync
async def test_a_connection_that_does_not_log_in_in_time_is_closed(tmp_path):
    async with lab_host(
        tmp_path, [Account("ann")], logins=LoginPolicy(login_timeout=0.5), fork_server=False
    ) as host:
        reader, writer = await idle_socket(host.port)
        assert await closed_within(reader, 3.0)
        writer.close()


@sync
async def test_agent_and_tunnel_requests_are_refused_and_logged(tmp_path, caplog):
    caplog.set_level(logging.INFO, logger="workbench.ssh")
    async with lab_host(tmp_path, [Account("ann")], fork_server=False) as host:
        conn = await host.connect("ann", agent_forwarding=True, agent_path="/nonexistent/agent")
        result = await conn.run("ls", check=False)  # the agent request comes with the session
        assert result.exit_status == 1
        with pytest.raises(asyncssh.ChannelOpenError):
            await conn.open_tun()
        conn.close()
        await until(lambda: "agent forwarding refused: ann from 127.0.0.1" in caplog.text)
        assert "tunnel (tun) refused: ann from 127.0.0.1" in caplog.text


@pytest.mark.skipif(
    shutil.which("ssh") is None or shutil.which("ssh-agent") is None,
    reason="no OpenSSH client and agent (Debian package openssh-client)",
)
@sync
async def test_x11_and_agent_forwarding_asked_by_openssh_are_logged(tmp_path, caplog):
    caplog.set_level(logging.INFO, logger="workbench.ssh")
    async with lab_host(tmp_path, [Account("ann")], fork_server=False) as host:
        key = tmp_path / "id_ann"
        key.write_bytes(host.accounts["ann"].key.export_private_key())
        key.chmod(0o600)
        argv = [
            "ssh", "-F", "/dev/null", "-i", str(key), "-p", str(host.port), "-X", "-A",
            "-o", "StrictHostKeyChecking=no", "-o", "UserKnownHostsFile=/dev/null",
            "-o", "BatchMode=yes", "ann@127.0.0.1", "true",
        ]  # fmt: skip
        sock = tmp_path / "agent.sock"
        agent = subprocess.Popen(["ssh-agent", "-D", "-a", str(sock)], stdout=subprocess.DEVNULL)
        try:
            for _ in range(100):
                if sock.exists():
                    break
                await asyncio.sleep(0.05)
            env = {"PATH": "/usr/bin:/bin", "DISPLAY": ":77", "SSH_AUTH_SOCK": str(sock)}
            done = await asyncio.to_thread(
                subprocess.run, argv, env=env, capture_output=True, text=True, timeout=30
            )
        finally:
            agent.terminate()
            agent.wait()
        assert "no commands" in done.stderr, done.stderr
        await until(lambda: "X11 forwarding refused: ann from 127.0.0.1" in caplog.text)
        assert "agent forwarding refused: ann from 127.0.0.1" in caplog.text
