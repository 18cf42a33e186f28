"""What one logged-in student can spend of the server process that carries every session,
attacked over loopback with asyncssh: session channels opened without end, channels that ask
for nothing, forwards past the channel cap, and the server short of memory."""

from __future__ import annotations

import asyncio
import gc
import logging

import asyncssh
import pytest

from tests.app.support import sync
from tests.waiting import until
from workbench.door.limits import SessionLimits
from workbench.door.memory import SHORT_OF_MEMORY
from workbench.ssh.server import LabSession

from .ssh_support import Account, lab_host, moved, open_bare_channel
from .test_ssh_limits import refused_reason

#: channel opens the attack tries past the cap (the live attack opened 393,600)
FLOOD = 2000


def live_lab_sessions() -> int:
    """The server's session-channel objects still held anywhere."""
    gc.collect()
    return sum(1 for o in gc.get_objects() if isinstance(o, LabSession) and not o._closed)


@sync
async def test_channels_past_the_cap_are_refused_in_one_line_and_others_still_get_a_screen(
    tmp_path, caplog
):
    caplog.set_level(logging.INFO, logger="workbench.ssh")
    limits = SessionLimits(channels_per_connection=4, channel_grace=60)
    accounts = [Account("mallory"), Account("ann")]
    async with lab_host(tmp_path, accounts, limits=limits) as host:
        term = await host.terminal("mallory")  # a workbench, one channel of the four
        await term.start_app()
        conn = term.conn
        held = [await open_bare_channel(conn) for _ in range(3)]
        refused = 0
        for _ in range(FLOOD):
            with pytest.raises(asyncssh.ChannelOpenError) as caught:
                await open_bare_channel(conn)
            refused += 1
        assert refused == FLOOD
        assert "4 channels open, the most one connection may have" in caught.value.reason
        # a forward to her own VIPLE port is a channel too
        (session,) = host.server.live("mallory")
        assert session.spec is not None
        with pytest.raises(asyncssh.ChannelOpenError) as caught:
            await conn.open_connection("localhost", session.spec.tcp_port)
        assert "the most one connection may have" in caught.value.reason
        # one log line for the whole flood, never one per channel
        lines = [r for r in caplog.records if "channel refused: mallory" in r.getMessage()]
        assert len(lines) == 1, [r.getMessage() for r in lines]
        (connection,) = [c for c in host.server.connections if c.user and c.username == "mallory"]
        assert connection.channels == 4
        assert live_lab_sessions() == 4  # the refused ones hold nothing on the server
        # her own workbench still answers her keys, and another student gets a screen
        term.send("w" * 8)
        await term.wait_until(moved, "mallory's robot moved")
        ann = await host.terminal("ann")
        await ann.start_app()
        # a channel closed gives its place back
        chan, _ = held.pop()
        chan.close()
        await until(lambda: connection.channels == 3, "the closed channel's place given back")
        held.append(await open_bare_channel(conn))
        for chan, _ in held:
            chan.close()
        await ann.close()
        await term.close()


@sync
async def test_a_channel_that_asks_for_nothing_is_closed_after_the_grace(tmp_path, caplog):
    caplog.set_level(logging.INFO, logger="workbench.ssh")
    limits = SessionLimits(channels_per_connection=10, channel_grace=0.5)
    async with lab_host(tmp_path, [Account("mallory")], limits=limits) as host:
        conn = await host.connect("mallory")
        opened = [await open_bare_channel(conn) for _ in range(10)]
        for _, session in opened:
            await asyncio.wait_for(session.closed.wait(), 20)
            assert b"closed a channel that asked for nothing" in session.said
            assert b"within 0.5 s" in session.said
        (connection,) = [c for c in host.server.connections if c.username == "mallory"]
        await until(lambda: connection.channels == 0, "every place given back")
        lines = [r for r in caplog.records if "asked for nothing" in r.getMessage()]
        assert len(lines) == 1, [r.getMessage() for r in lines]
        # the places are free again: ten more may be opened
        again = [await open_bare_channel(conn) for _ in range(10)]
        for chan, _ in again:
            chan.close()
        conn.close()


@sync
async def test_short_of_memory_the_server_refuses_new_work_and_keeps_live_sessions(
    tmp_path, caplog
):
    caplog.set_level(logging.INFO, logger="workbench.ssh")
    accounts = [Account("ann"), Account("bob"), Account("mallory")]
    async with lab_host(tmp_path, accounts) as host:
        ann = await host.terminal("ann")
        await ann.start_app()
        mallory = await host.connect("mallory")  # logged in before the pressure
        memory = host.server.memory
        memory.ceiling = 1  # MiB: far below what the server uses
        memory.refresh()
        for _ in range(3):
            assert (await refused_reason(host, "bob")).startswith(SHORT_OF_MEMORY)
        with pytest.raises(asyncssh.ChannelOpenError) as caught:
            await open_bare_channel(mallory)
        assert caught.value.reason == SHORT_OF_MEMORY
        lines = [r for r in caplog.records if "past its ceiling" in r.getMessage()]
        assert len(lines) == 1, [r.getMessage() for r in lines]
        assert "refused: the server uses" in lines[0].getMessage()
        # the live session goes on
        ann.send("w" * 8)
        await ann.wait_until(moved, "ann's robot moved")
        memory.ceiling = 1 << 20  # the pressure is over: new work is taken again
        memory.refresh()
        bob = await host.terminal("bob")
        await bob.start_app()
        for closing in (bob, ann):
            await closing.close()
        mallory.close()


@sync
async def test_a_flood_of_typed_keys_is_dropped_past_the_budget_and_the_app_answers(tmp_path):
    async with lab_host(tmp_path, [Account("mallory")]) as host:
        term = await host.terminal("mallory")
        await term.start_app()
        term.send("z" * 65536)  # 64 KiB of typed keys in one go (each a key event)
        await term.wait_for("typed keys were dropped")
        term.send("p")
        await term.wait_for("PAUSED")
        await term.close()
