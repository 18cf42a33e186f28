"""Two students on the lab server at once: each has their own robot and VIPLE ports, and SSH
forwarding reaches only the student's own."""

from __future__ import annotations

import asyncio
import contextlib
import json
import os
import re

import asyncssh
import pytest

from tests.app.support import sync
from workbench.files.workspace import BUNDLED
from workbench.labs.store.store import Store

from .ssh_support import PASSWORD, Account, distance, lab_host, moved

MOVE = b'{"servos":[{"isTurn":false,"servoId":-1,"servoSpeed":1}]}\r\n'


def units(text: str) -> float:
    """The run panel's distance in units (0 when not on the screen)."""
    shown = distance(text)
    return float(shown.split()[0]) if shown else 0.0


def app_time(text: str) -> float:
    """The simulated time the run panel shows ("running at 1x | t 2.3 s")."""
    found = re.search(r"\bt (\d+\.\d) s\b", text)
    assert found, text
    return float(found.group(1))


async def tcp_port_shown(term) -> int:
    """The VIPLE TCP port from the forwarding command the app shows in its help."""
    term.send("?")
    screen = await term.wait_for("Connect VIPLE", "-L 1350:localhost:")
    term.send("\x1b")
    await term.wait_gone("Connect VIPLE")
    found = re.search(r"-L 1350:localhost:(\d+)", screen)
    assert found, f"no forwarding command on the screen:\n{screen}"
    return int(found.group(1))


@sync
async def test_each_student_sees_only_their_robot_and_forwards_only_to_their_own_ports(tmp_path):
    async with lab_host(tmp_path, [Account("ann"), Account("ben")]) as host:
        ann, ben = await asyncio.gather(host.terminal("ann"), host.terminal("ben"))
        await asyncio.gather(ann.start_app(), ben.start_app())
        port_a, port_b = await asyncio.gather(tcp_port_shown(ann), tcp_port_shown(ben))
        assert port_a != port_b
        ws_a = host.server.live("ann")[0].spec.ws_port
        ws_b = host.server.live("ben")[0].spec.ws_port

        # A drives; B's robot stays where it is
        ann.send("w")
        await ann.wait_until(moved, "ann's robot moving")
        ben.send(" ")  # a key for ben too, so both apps are equally awake
        await ann.wait_until(lambda t: units(t) >= 0.5, "ann's robot half a unit on")
        assert "distance 0.00 unit" in ben.text()

        # a second connection of A's, like `ssh -N -L ...` on the student's computer
        tunnel = await host.connect("ann")
        with pytest.raises(asyncssh.ChannelOpenError, match="forward refused"):
            await tunnel.open_connection("localhost", port_b)
        with pytest.raises(asyncssh.ChannelOpenError, match="forward refused"):
            await tunnel.open_connection("10.1.2.3", port_a)
        with pytest.raises(asyncssh.ChannelListenError):
            await tunnel.forward_remote_port("localhost", ws_b, "localhost", 8124)

        # A's own port works: a VIPLE-style client through the forward drives A's robot
        ann.send(" ")  # stop the keys' run first
        listener = await tunnel.forward_local_port("127.0.0.1", 0, "localhost", port_a)
        reader, writer = await asyncio.open_connection("127.0.0.1", listener.get_port())
        report = json.loads(await asyncio.wait_for(reader.readline(), 10))
        assert [entry["id"] for entry in report["sensors"]] == [1, 2]
        writer.write(MOVE)
        await writer.drain()
        screen = await ann.wait_for("driver: VIPLE tcp", timeout=10)
        before = screen
        await ann.wait_until(lambda t: t != before and moved(t), "ann's robot driven by VIPLE")
        assert "distance 0.00 unit" in ben.text()
        assert "driver: keys" in ben.text()  # nobody's VIPLE drives ben's robot

        writer.close()  # VIPLE over TCP lets go of the robot
        with contextlib.suppress(Exception):
            await writer.wait_closed()

        # then the app reaches A's VIPLE WebSocket server through A's own remote forward
        arrived = asyncio.Event()

        async def viple_ws(r: asyncio.StreamReader, w: asyncio.StreamWriter) -> None:
            arrived.set()
            w.close()

        local = await asyncio.start_server(viple_ws, "127.0.0.1", 0)
        local_port = local.sockets[0].getsockname()[1]
        await tunnel.forward_remote_port("localhost", ws_a, "127.0.0.1", local_port)
        # a second of the app's own clock: no attempts (and no errors in ssh -N) until asked
        then = app_time(ann.text())
        await ann.wait_until(lambda t: app_time(t) >= then + 1.0, "a second on ann's clock")
        assert not arrived.is_set()
        ann.send("v")  # connect over WebSocket
        await asyncio.wait_for(arrived.wait(), 15)

        local.close()
        listener.close()
        tunnel.close()
        await asyncio.gather(ann.close(), ben.close())


def dialog_says(phrase: str):
    """A check that a dialog's text holds ``phrase``, however its lines are wrapped."""

    def check(screen: str) -> bool:
        inside = []
        for line in screen.splitlines():
            edges = [i for i, c in enumerate(line) if c in "│|"]  # Unicode or ASCII frames
            if len(edges) >= 2:
                inside.append(line[edges[0] + 1 : edges[-1]])
        return phrase in " ".join(" ".join(inside).split())

    return check


async def type_in(term, text: str) -> None:
    """Clear the focused field (ctrl+u), type ``text`` and Enter in one burst, as SSH sends."""
    term.send("\x15" + text + "\r")


@sync
async def test_a_student_reaches_only_their_workspace_and_cannot_change_the_server_s_files(
    tmp_path,
):
    async with lab_host(tmp_path, [Account("ann"), Account("ben", password=PASSWORD)]) as host:
        data = host.data_dir
        users = data / "ssh-users.yaml"
        Store.open(data).close()  # the section's progress and sign-offs
        database = data / "workbench.sqlite3"
        ben_space = data / "workspaces" / "ben"
        ben_space.mkdir(parents=True)
        (ben_space / "ben.txt").write_text("#####\n#S  #\n#  E#\n#####\n")
        term = await host.terminal("ann")
        await term.start_app()
        ann_space = data / "workspaces" / "ann"
        assert ann_space.is_dir() and ann_space.stat().st_mode & 0o777 == 0o700
        os.symlink(users, ann_space / "notes.txt")  # however a link got there, it leads nowhere
        before = {p: p.read_bytes() for p in (users, database, ben_space / "ben.txt")}

        for attempt in ("../../ssh-users.yaml", str(users), "../ben/ben.txt", "notes.txt"):
            term.send("m")
            await term.wait_for("Load a maze", "your workspace, ~/")
            await type_in(term, attempt)
            await term.wait_until(dialog_says("is outside your workspace"), attempt)
            screen = term.text()
            assert "scrypt" not in screen and "ssh-ed25519" not in screen, screen
            term.send("\x1b")
            # the whole dialog gone (a frame read half-drawn may lack its title alone)
            await term.wait_until(
                lambda t: "Load a maze" not in t and "outside your workspace" not in t,
                "the dialog closed",
            )

        term.send("e")  # the editor, on the bundled maze
        await term.wait_for("Maze editor")
        term.send(" \x13")  # a change, then ctrl+s: asks where to keep the copy
        await term.wait_for("Save maze as")
        await type_in(term, str(BUNDLED[0] / "unity-default.txt"))
        await term.wait_until(dialog_says("is a bundled file, kept as shipped"), "bundled")
        for attempt in ("../../workbench.sqlite3", str(users), "notes.txt"):
            await type_in(term, attempt)
            named = attempt.rsplit("/", 1)[-1]  # a long path is wrapped inside words
            await term.wait_until(dialog_says(f"{named} is outside your workspace"), attempt)
            assert "scrypt" not in term.text()
        await type_in(term, "~/copy.txt")
        await term.wait_for("saved to ~/copy.txt")
        assert (ann_space / "copy.txt").is_file()
        await term.close()
        assert {p: p.read_bytes() for p in before} == before
