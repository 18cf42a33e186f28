"""The lab server behind a load balancer (``--proxy-protocol``), over real loopback SSH: the
address in the balancer's PROXY header is the one the login log and the per-address caps see,
a connection from the balancer without a valid header is closed with one log line, and a
connection from anywhere else is never read for a header."""

from __future__ import annotations

import asyncio
import contextlib
import logging
import socket

import asyncssh

from tests.app.support import sync
from tests.waiting import until
from workbench.door.logins import LoginPolicy
from workbench.door.networks import parse_networks

from ..unit.test_proxy_protocol import v2
from .ssh_support import Account, lab_host

BALANCER = parse_networks("127.0.0.1")


async def through_balancer(port: int, header: bytes) -> socket.socket:
    """A connection from 127.0.0.1 that starts with ``header``, as the balancer's would."""
    loop = asyncio.get_running_loop()
    sock = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
    sock.setblocking(False)
    await loop.sock_connect(sock, ("127.0.0.1", port))
    await loop.sock_sendall(sock, header)
    return sock


async def login_as(host, name: str, sock: socket.socket) -> asyncssh.SSHClientConnection:
    return await asyncssh.connect(
        sock=sock,
        username=name,
        client_keys=[host.accounts[name].key],
        known_hosts=None,
        agent_path=None,
    )


async def what_it_reads(sock: socket.socket) -> bytes:
    """All the server sends until it closes the connection (a reset too: the server closed
    with bytes it did not read)."""
    loop = asyncio.get_running_loop()
    said = b""
    async with asyncio.timeout(20):
        with contextlib.suppress(ConnectionResetError):
            while chunk := await loop.sock_recv(sock, 4096):
                said += chunk
    return said


@sync
async def test_a_student_behind_the_balancer_logs_in_under_the_address_its_header_names(
    tmp_path, caplog
):
    caplog.set_level(logging.INFO, logger="workbench.ssh")
    async with lab_host(tmp_path, [Account("ana")], proxy_from=BALANCER, fork_server=False) as host:
        conn = await login_as(host, "ana", await through_balancer(host.port, v2("192.0.2.7")))
        assert "login: ana (student) from 192.0.2.7 with key" in caplog.text
        assert host.server.user_connections["ana"] == 1
        conn.close()
        await conn.wait_closed()


@sync
async def test_the_per_address_cap_counts_the_address_in_the_header_not_the_balancer(
    tmp_path, caplog
):
    caplog.set_level(logging.INFO, logger="workbench.ssh")
    policy = LoginPolicy(
        max_unauthenticated_per_address=1, unauthenticated_grace=60, login_timeout=60
    )
    accounts = [Account("ana")]
    async with lab_host(
        tmp_path, accounts, logins=policy, proxy_from=BALANCER, fork_server=False
    ) as host:
        gate = host.server.gate
        idle = await through_balancer(host.port, v2("192.0.2.7"))  # holds 192.0.2.7's place
        await until(lambda: gate.unauthenticated["192.0.2.7"] == 1, "the idle connection held")
        refused = await through_balancer(host.port, v2("192.0.2.7"))
        assert b"too many connections waiting to log in" in await what_it_reads(refused)
        assert "connection from 192.0.2.7 closed: 1 connections from this address" in caplog.text
        # another student behind the same balancer is not counted with them
        conn = await login_as(host, "ana", await through_balancer(host.port, v2("198.51.100.4")))
        conn.close()
        assert "login: ana (student) from 198.51.100.4" in caplog.text
        for sock in (idle, refused):
            sock.close()


@sync
async def test_a_connection_from_the_balancer_without_a_header_is_closed_with_one_log_line(
    tmp_path, caplog
):
    caplog.set_level(logging.INFO, logger="workbench.ssh")
    async with lab_host(tmp_path, [Account("ana")], proxy_from=BALANCER, fork_server=False) as host:
        garbage = await through_balancer(host.port, b"SSH-2.0-OpenSSH_9.6\r\n")
        assert await what_it_reads(garbage) == b""  # closed before the server said anything
        line = "connection from 127.0.0.1 closed: it did not start with a PROXY protocol header"
        await until(lambda: line in caplog.text, "the refusal logged")
        oversized = v2("192.0.2.7")[:14] + b"\xff\xff"
        assert await what_it_reads(await through_balancer(host.port, oversized)) == b""
        # a health check (a bare TCP connection, or a LOCAL header) is closed without a word
        check = await through_balancer(host.port, b"")
        check.close()
        local = await through_balancer(host.port, v2("127.0.0.1", command=0) + b"SSH-2.0-x\r\n")
        assert await what_it_reads(local) == b""
        local.close()
        conn = await login_as(host, "ana", await through_balancer(host.port, v2("192.0.2.7")))
        conn.close()
        garbage.close()
        assert "Traceback" not in caplog.text
        closed = [r for r in caplog.records if "closed" in r.getMessage()]
        assert len(closed) == 1  # the oversized one, within 10 s of it, is held back


@sync
async def test_a_header_that_never_comes_closes_the_connection_after_the_login_timeout(
    tmp_path, caplog
):
    caplog.set_level(logging.INFO, logger="workbench.ssh")
    policy = LoginPolicy(login_timeout=0.5)
    async with lab_host(
        tmp_path, [Account("ana")], logins=policy, proxy_from=BALANCER, fork_server=False
    ) as host:
        silent = await through_balancer(host.port, v2("192.0.2.7")[:10])
        assert await what_it_reads(silent) == b""
        assert "connection from 127.0.0.1 closed: no PROXY header within 0.5 s" in caplog.text
        silent.close()


@sync
async def test_a_client_not_from_the_balancer_is_not_read_for_a_header(tmp_path, caplog):
    caplog.set_level(logging.INFO, logger="workbench.ssh")
    elsewhere = parse_networks("10.0.0.0/24")
    async with lab_host(
        tmp_path, [Account("ana")], proxy_from=elsewhere, fork_server=False
    ) as host:
        conn = await host.connect("ana")
        conn.close()
        assert "login: ana (student) from 127.0.0.1" in caplog.text
        # a student who writes a header of their own is not believed: SSH refuses it
        spoof = await through_balancer(host.port, v2("192.0.2.7"))
        await what_it_reads(spoof)
        spoof.close()
        assert "192.0.2.7" not in caplog.text
