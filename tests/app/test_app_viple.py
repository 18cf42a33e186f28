"""The app hosts the VIPLE endpoints on its own robot and shows their status."""

from __future__ import annotations

import asyncio
import socket

from tests.sessions import free_port
from workbench.tui.app import WorkbenchApp, make_app
from workbench.tui.settings import AppSettings
from workbench.tui.widgets.run_status import RunStatus

ROOM = "#########\n#.......#\n#...S...#\n#.......#\n#########\n"


def maze(tmp_path) -> str:
    path = tmp_path / "room.txt"
    path.write_text(f"---\nname: room\nprofile: erobotic\n---\n{ROOM}")
    return str(path)


def status(app: WorkbenchApp) -> str:
    return "\n".join(app.screen.query_one(RunStatus).lines)


def test_a_viple_program_drives_the_robot_the_app_shows(tmp_path):
    port = free_port()
    app = make_app(AppSettings(maze(tmp_path), tcp_port=port, noise="off", tick_hz=50))

    async def go() -> None:
        async with app.run_test(size=(80, 24)) as pilot:
            await pilot.pause(0.1)
            assert f"VIPLE tcp listening on 127.0.0.1:{port}" in status(app)
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
            assert "in 1 out" in status(app)
            writer.write(b"not json\r\n")
            await writer.drain()
            await pilot.pause(0.2)
            assert "1 rejected (last: line 2: not JSON" in status(app)
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
        app = make_app(AppSettings(maze(tmp_path), tcp_port=port, noise="off", paused=True))

        async def go() -> None:
            async with app.run_test(size=(80, 24)) as pilot:
                await pilot.pause(0.1)
                assert f"VIPLE tcp not listening: port {port} is in use" in status(app)
                await pilot.press("d")
                await pilot.press("n")
                assert app.station.keys_used == {"d"}

        asyncio.run(go())
