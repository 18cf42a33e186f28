"""The app hosts the VIPLE endpoints on its own robot and shows their status."""

from __future__ import annotations

import asyncio
import re
import socket

from textual.command import CommandList

from tests.sessions import free_port
from tests.waiting import until
from workbench.tui.app import WorkbenchApp, make_app
from workbench.tui.dialogs.identity import IdentityDialog
from workbench.tui.screens.main import MainScreen
from workbench.wire.settings import AppSettings

from .support import maze_file, run, run_panel, said

ROOM = "#########\n#.......#\n#...S...#\n#.......#\n#########\n"


def test_a_viple_program_drives_the_robot_the_app_shows(tmp_path):
    port = free_port()
    app = make_app(
        AppSettings(maze_file(tmp_path, ROOM, "erobotic"), tcp_port=port, noise="off", tick_hz=50)
    )

    async def go() -> None:
        async with app.run_test(size=(80, 24)) as pilot:
            await pilot.pause(0.1)
            assert f"VIPLE tcp listening on 127.0.0.1:{port}" in run_panel(app)
            reader, writer = await asyncio.open_connection("127.0.0.1", port)
            report = await asyncio.wait_for(reader.readline(), 2)
            assert report.startswith(b'{"sensors":[')
            x0 = app.station.snapshot().pose.x
            writer.write(b'{"servos":[{"isTurn":false,"servoId":-1,"servoSpeed":"1"}]}\r\n')
            await writer.drain()
            await pilot.pause(0.5)
            snap = app.station.snapshot()
            assert snap.pose.x > x0 + 20  # heading right at 120 px/s
            assert str(snap.driver).startswith("VIPLE tcp 127.0.0.1:")
            assert "in 1 out" in run_panel(app)
            writer.write(b"not json\r\n")
            await writer.drain()
            await pilot.pause(0.2)
            assert "1 rejected (last: line 2: not JSON" in run_panel(app)
            writer.close()
            await pilot.pause(0.3)
            x1 = app.station.snapshot().pose.x
            await pilot.pause(0.2)
            assert app.station.snapshot().pose.x == x1  # the robot stopped when VIPLE went
            await pilot.press("ctrl+q")

    asyncio.run(go())


def test_a_port_in_use_is_shown_and_the_app_keeps_working(tmp_path):
    with socket.socket() as taken:
        taken.bind(("127.0.0.1", 0))
        taken.listen()
        port = taken.getsockname()[1]
        app = make_app(
            AppSettings(
                maze_file(tmp_path, ROOM, "erobotic"), tcp_port=port, noise="off", paused=True
            )
        )

        async def go() -> None:
            async with app.run_test(size=(80, 24)) as pilot:
                await pilot.pause(0.1)
                assert f"VIPLE tcp not listening: port {port} is in use" in run_panel(app)
                await pilot.press("d")
                await pilot.press("n")
                assert app.station.keys_used == {"d"}

        asyncio.run(go())


# -- the real clock for a live program ---------------------------------------------------------
MOVE = b'{"servos":[{"isTurn":false,"servoId":-1,"servoSpeed":"1"}]}\r\n'


Peer = tuple[asyncio.StreamReader, asyncio.StreamWriter]


async def connected(app: WorkbenchApp, port: int) -> Peer:
    """A scripted VIPLE program connected to the app's TCP port, holding the robot."""
    reader, writer = await asyncio.open_connection("127.0.0.1", port)
    await asyncio.wait_for(reader.readline(), 5)
    await until(lambda: app.station.live_viple is not None, "the program holds the robot")
    return reader, writer


async def palette_runs(pilot, words: str) -> None:
    """Run the command palette's first command for ``words``."""
    app = pilot.app
    await pilot.press("ctrl+p")
    await pilot.pause()
    await pilot.press(*words)
    await until(lambda: app.screen.query_one(CommandList).option_count, "the palette's hits")
    await pilot.press("enter")
    await until(lambda: isinstance(app.screen, MainScreen), "the palette closed")


def test_a_live_program_runs_at_1x_and_the_speed_keys_say_why_they_are_held(tmp_path):
    port = free_port()
    app = make_app(AppSettings(maze_file(tmp_path, ROOM, "erobotic"), tcp_port=port, noise="off"))

    async def body(pilot) -> None:
        await pilot.press("+", "+", "+", "+")  # 2x, 4x, 10x, max: left from before
        assert app.station.pacer.speed is None
        _reader, writer = await connected(app, port)
        assert app.station.pacer.speed == 1.0
        await until(lambda: "running at 1x" in run_panel(app), "the panel at 1x")
        await pilot.press("+")
        await until(lambda: "speed held at 1x while VIPLE tcp 127.0.0.1:" in said(app))
        assert "its Timers count real time" in said(app) and app.station.pacer.speed == 1.0
        app.say("")
        await palette_runs(pilot, "speed")  # the palette's speed command, the same
        await until(lambda: "speed held at 1x" in said(app), "the palette's speed held")
        assert app.station.pacer.speed == 1.0
        writer.close()
        await until(lambda: app.station.live_viple is None, "the program let go")
        await until(lambda: "speed held" not in said(app), "the held message goes with it")
        await pilot.press("+")
        await until(lambda: app.station.pacer.speed == 2.0, "the speed key works again")

    run(app, body)


def test_a_paused_station_says_the_programs_commands_are_held_and_counts_on(tmp_path):
    port = free_port()
    app = make_app(AppSettings(maze_file(tmp_path, ROOM, "erobotic"), tcp_port=port, noise="off"))

    async def body(pilot) -> None:
        reader, writer = await connected(app, port)
        await pilot.press("p")
        assert app.station.paused
        assert "commands are held, not applied, until p resumes" in said(app)
        pose = app.station.snapshot().pose
        for _ in range(3):
            writer.write(MOVE)
            await writer.drain()
            await asyncio.wait_for(reader.readline(), 5)  # still answered with a report
        await until(lambda: "3 commands held while paused, not applied" in run_panel(app))
        # the panel's counters keep counting while paused (the clock ticks at rest)
        await until(lambda: re.search(r": in 3 out \d+", run_panel(app)), "the counters")
        assert app.station.snapshot().pose == pose
        await pilot.press("p")  # time runs again: the program's last command drives
        await until(lambda: app.station.snapshot().pose.x > pose.x + 5, "the robot moving")
        assert "held" not in run_panel(app)
        writer.close()

    run(app, body)


def test_a_reset_and_the_end_of_a_run_put_the_speed_back_to_1x(tmp_path):
    app = make_app(AppSettings(maze_file(tmp_path, ROOM, "erobotic"), noise="off", paused=True))

    async def body(pilot) -> None:
        await pilot.press("+", "+", "+", "+")
        assert "at max" in run_panel(app)
        await pilot.press("r")
        await until(lambda: "PAUSED at 1x" in run_panel(app), "1x after a reset")
        await pilot.press("+", "+", "d")  # 4x, a run by the keys
        assert app.station.pacer.speed == 4.0
        app.station.select_algorithm("right-wall")
        app.station.apply_algorithm_preset()
        await pilot.press("x")  # a new run at the speed chosen; the keys' run ended
        assert app.station.driving is not None and app.station.pacer.speed == 4.0
        await pilot.press("x")  # stopped: the run is over
        await until(lambda: app.station.pacer.speed == 1.0, "1x after the run")
        assert "at 1x" in run_panel(app)

    run(app, body)


def test_no_time_passes_while_the_names_are_asked(tmp_path):
    maze = maze_file(tmp_path, ROOM, "erobotic")
    app = make_app(AppSettings(maze, noise="off", ask_names=True, student="ann",
                               data_dir=tmp_path / "data"))  # fmt: skip

    async def body(pilot) -> None:
        assert isinstance(app.screen, IdentityDialog)
        ticks: list[int] = []  # the steps each tick gave the station
        advance = app._advance
        app._advance = lambda: ticks.append(advance()) or ticks[-1]  # type: ignore[method-assign]
        # the clock has ticked (at its full rate, then at rest) with the dialog open
        await until(lambda: len(ticks) >= 2 and app._resting, "ticks behind the dialog")
        assert ticks == [0] * len(ticks) and app.station.session.world.time == 0.0
        await pilot.press("enter")
        await until(lambda: isinstance(app.screen, MainScreen), "the main screen")
        assert app.station.session.world.time < 0.5  # the first run starts from here

    run(app, body)


def test_a_program_that_connects_to_a_paused_station_is_told_its_commands_wait(tmp_path):
    port = free_port()
    app = make_app(
        AppSettings(maze_file(tmp_path, ROOM, "erobotic"), tcp_port=port, noise="off", paused=True)
    )

    async def body(pilot) -> None:
        reader, writer = await connected(app, port)
        writer.write(MOVE)
        await writer.drain()
        await asyncio.wait_for(reader.readline(), 5)
        await until(lambda: "commands are held, not applied" in said(app), "the message line")
        assert "1 command held while paused, not applied" in run_panel(app)
        writer.close()

    run(app, body)
