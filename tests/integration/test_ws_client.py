"""The Web-Simulator role against a `websockets` server standing in for VIPLE, on loopback."""

from __future__ import annotations

import asyncio
import json
import logging
import socket

import pytest
from websockets.asyncio.server import ServerConnection, serve
from websockets.exceptions import ConnectionClosed

from tests.sessions import (
    CORRIDOR,
    free_port,
    many_sensors,
    pushes_keep_their_interval,
    session_for,
    steps,
)
from tests.waiting import until
from workbench.sim.session import Session
from workbench.viple import ws_client
from workbench.viple.codec import parse_report
from workbench.viple.link import Seat
from workbench.viple.tcp_server import TcpConfig, TcpServer
from workbench.viple.ws_client import RETRY_SECONDS, WsClient, WsConfig, check_ws_url

MOVE = '{"servos":[{"isTurn":false,"servoId":-1,"servoSpeed":1}]}'
STOP = '{"servos":[{"isTurn":false,"servoId":-1,"servoSpeed":"0"}]}'
DRIVE = (
    '{"servos":[{"isTurn":false,"servoId":3,"servoSpeed":0.5},'
    '{"isTurn":false,"servoId":5,"servoSpeed":0.5}]}'
)
RETRY = 0.1


class FakeViple:
    """VIPLE's WebSocket server: accepts the robot, sends frames, collects what arrives."""

    def __init__(self, port: int) -> None:
        self.port = port
        self.url = f"ws://127.0.0.1:{port}/"
        self.server = None
        self.robot: ServerConnection | None = None
        self.arrived = asyncio.Event()
        self.messages: asyncio.Queue[str | bytes] = asyncio.Queue()

    async def start(self) -> FakeViple:
        self.arrived = asyncio.Event()
        self.server = await serve(self._robot, "127.0.0.1", self.port, max_size=None)
        return self

    async def stop(self) -> None:
        self.server.close()
        await self.server.wait_closed()

    async def _robot(self, ws: ServerConnection) -> None:
        self.robot = ws
        self.arrived.set()
        try:
            async for message in ws:
                await self.messages.put(message)
        except ConnectionClosed:
            pass

    async def connected(self, timeout: float = 2.0) -> ServerConnection:
        await asyncio.wait_for(self.arrived.wait(), timeout)
        return self.robot

    async def report(self, timeout: float = 2.0) -> dict[int, float]:
        message = await asyncio.wait_for(self.messages.get(), timeout)
        assert isinstance(message, str)
        return parse_report(message)

    async def drop_reports(self) -> None:
        while not self.messages.empty():
            self.messages.get_nowait()


def client_for(session: Session, url: str, **config) -> WsClient:
    return WsClient(session, WsConfig(url=url, retry_seconds=RETRY, **config))


def attempts(monkeypatch) -> list[str]:
    """The URLs the client has tried to connect to so far, one entry per attempt."""
    tried: list[str] = []
    connect = ws_client.connect

    def counted(url: str, **options):
        tried.append(url)
        return connect(url, **options)

    monkeypatch.setattr(ws_client, "connect", counted)
    return tried


def messages(caplog, text: str) -> list[str]:
    return [r.getMessage() for r in caplog.records if text in r.getMessage()]


def test_started_before_viple_it_retries_quietly_until_viple_appears(caplog, monkeypatch):
    caplog.set_level(logging.INFO, logger="workbench.viple")
    tried = attempts(monkeypatch)

    async def scenario():
        viple = FakeViple(free_port())
        session = session_for()
        async with client_for(session, viple.url) as client:
            await until(lambda: len(tried) >= 5, "five attempts")  # each one failed
            assert not client.status.connected
            await viple.start()
            await viple.connected()
            report = await viple.report()
            assert sorted(report) == [1, 2]
            assert client.status.connected and client.status.peer == viple.url
            assert str(session.driver) == f"VIPLE ws {viple.url}"
        await viple.stop()

    asyncio.run(scenario())
    assert len(messages(caplog, "is not reachable")) == 1  # once per outage
    assert len(messages(caplog, "connected to VIPLE at")) == 1


def test_commands_in_frames_move_the_robot_and_each_is_answered():
    async def scenario():
        viple = await FakeViple(free_port()).start()
        session = session_for()
        async with client_for(session, viple.url, report_ms=1000) as client:
            robot = await viple.connected()
            await viple.report()  # pushed on connect
            await robot.send(MOVE)
            await viple.report(timeout=0.5)  # the answer, long before the next push
            x = session.world.pose.x
            steps(session, 60)
            assert session.world.pose.x == pytest.approx(x + 1.0, abs=0.02)
            # several CRLF-separated objects in one frame
            await robot.send(STOP + "\r\n" + MOVE + "\r\n")
            await viple.report(timeout=0.5)
            await viple.report(timeout=0.5)
            assert client.status.messages_in == 3 and client.status.invalid == 0
            steps(session, 30)
            assert session.world.pose.x == pytest.approx(x + 1.5, abs=0.02)
        await viple.stop()

    asyncio.run(scenario())


def test_reports_arrive_at_the_configured_interval_and_never_early():
    async def scenario():
        viple = await FakeViple(free_port()).start()
        loop = asyncio.get_running_loop()
        start = loop.time()
        async with client_for(session_for(), viple.url, report_ms=100):
            await viple.connected()
            await pushes_keep_their_interval(
                lambda: viple.report(timeout=20), loop.time, start, 0.1, count=6
            )
        await viple.stop()

    asyncio.run(scenario())


def test_viple_restarting_stops_the_robot_and_the_client_reconnects(caplog, monkeypatch):
    caplog.set_level(logging.INFO, logger="workbench.viple")
    tried = attempts(monkeypatch)

    async def scenario():
        port = free_port()
        viple = await FakeViple(port).start()
        session = session_for(profile="web")
        async with client_for(session, viple.url) as client:
            robot = await viple.connected()
            await robot.send(DRIVE)
            await viple.report()
            await viple.stop()
            await until(lambda: not client.status.connected)
            assert str(session.driver) == "nobody"
            x = session.world.pose.x
            steps(session, 30)
            assert session.world.pose.x == pytest.approx(x)  # motors stopped
            down = len(tried)
            await until(lambda: len(tried) >= down + 3, "three attempts")  # VIPLE is down

            viple = await FakeViple(port).start()
            robot = await viple.connected()
            await viple.drop_reports()
            await robot.send(DRIVE)
            await until(lambda: client.status.messages_in == 2)
            steps(session, 60)
            assert session.world.pose.x == pytest.approx(x + 70.0, abs=1.0)
            assert client.status.connections == 2
        await viple.stop()

    asyncio.run(scenario())
    assert len(messages(caplog, "went away")) == 1
    assert messages(caplog, "is not reachable") == []  # the outage was already reported


def test_binary_frames_are_rejected_and_an_oversized_frame_closes_the_connection(caplog):
    caplog.set_level(logging.INFO, logger="workbench.viple")

    async def scenario():
        viple = await FakeViple(free_port()).start()
        session = session_for()
        async with client_for(session, viple.url) as client:
            robot = await viple.connected()
            await robot.send(b"\x00\x01binary")
            await robot.send("not json")
            await robot.send(MOVE)
            await until(lambda: client.status.messages_in == 3)
            assert client.status.invalid == 2 and client.status.connected
            viple.arrived.clear()
            await robot.send('{"servos":[' + " " * 70_000 + "]}")
            await until(lambda: client.status.invalid == 3)
            assert await _closed(robot)
            assert "longer than 65536 bytes" in client.status.last_rejection
            await viple.connected()  # it came back
            await until(lambda: client.status.connected)
            assert client.status.connections == 2
        await viple.stop()

    asyncio.run(scenario())
    assert messages(caplog, "binary frame of 8 bytes rejected")
    assert messages(caplog, "frame longer than 65536 bytes; connection closed")


async def _closed(ws: ServerConnection) -> bool:
    await asyncio.wait_for(ws.wait_closed(), 2.0)
    return True


def test_the_ws_role_waits_while_a_tcp_program_drives_the_same_robot(caplog, monkeypatch):
    caplog.set_level(logging.INFO, logger="workbench.viple")
    tried = attempts(monkeypatch)
    looks: list[bool] = []  # each time the client looked at the seat: whether it was taken
    seat_taken = WsClient._seat_taken
    monkeypatch.setattr(
        WsClient, "_seat_taken", lambda self: looks.append(seat_taken(self)) or looks[-1]
    )

    async def scenario():
        viple = await FakeViple(free_port()).start()
        session = session_for()
        seat = Seat()
        async with TcpServer(session, TcpConfig(port=0), seat) as tcp:
            reader, writer = await asyncio.open_connection("127.0.0.1", tcp.port)
            await reader.readline()
            config = WsConfig(url=viple.url, retry_seconds=RETRY)
            async with WsClient(session, config, seat) as client:
                # the seat is taken at every look, and the client never tries to connect
                await until(lambda: looks.count(True) >= 3, "three looks at the seat")
                assert tried == [] and not viple.arrived.is_set()
                writer.close()
                await viple.connected()
                await until(lambda: client.status.connected)
                assert str(session.driver) == f"VIPLE ws {viple.url}"
                # and now a TCP program is the one refused
                reader, writer = await asyncio.open_connection("127.0.0.1", tcp.port)
                error = json.loads(await reader.readline())
                assert error["error"].endswith(f"(from {viple.url})")
                writer.close()
        await viple.stop()

    asyncio.run(scenario())
    assert len(messages(caplog, "is driving the robot; connecting to VIPLE when it is free")) == 1


def test_urls_are_checked_and_the_retry_is_every_second_by_default():
    assert RETRY_SECONDS == 1.0 and WsConfig().retry_seconds == 1.0
    assert WsConfig().url == "ws://localhost:8124/"
    assert check_ws_url(" ws://[::1]:8124/ ") == "ws://[::1]:8124/"
    for bad, why in [
        ("", "empty"),
        ("http://localhost:8124/", "scheme isn't ws or wss"),
        ("ws://", "hostname isn't provided"),
        ("ws://localhost:99999/", "out of range"),
        ("localhost:8124", "not usable"),
    ]:
        with pytest.raises(ValueError, match=why):
            check_ws_url(bad)


# --- hostile and vanished drivers ------------------------------------------------------------


def test_a_number_with_a_control_character_is_rejected_and_the_same_connection_then_drives(
    caplog,
):
    caplog.set_level(logging.INFO, logger="workbench.viple")

    async def scenario():
        viple = await FakeViple(free_port()).start()
        session = session_for()
        async with client_for(session, viple.url) as client:
            robot = await viple.connected()
            await robot.send('{"servos":[{"servoId":3,"servoSpeed":"\\u001e0.5"}]}')
            await robot.send(MOVE)
            await until(lambda: client.status.messages_in == 2)
            assert client.status.invalid == 1
            assert client.status.connected and client.status.connections == 1
            x = session.world.pose.x
            steps(session, 60)
            assert session.world.pose.x == pytest.approx(x + 1.0, abs=0.02)
            # VIPLE ends the connection itself
            await robot.close()
            await until(lambda: not client.status.connected)
        await viple.stop()

    asyncio.run(scenario())
    assert messages(caplog, 'rejected line 1: servos[0].servoSpeed "\\u001e0.5" is not a number')
    assert messages(caplog, "disconnected (closed by VIPLE with code 1000")
    assert not any(r.exc_info for r in caplog.records)


def test_stopping_the_workbench_under_a_driver_says_so(caplog):
    caplog.set_level(logging.INFO, logger="workbench.viple")

    async def scenario():
        viple = await FakeViple(free_port()).start()
        session = session_for()
        async with client_for(session, viple.url):
            await viple.connected()
            await viple.report()
        assert str(session.driver) == "nobody"
        await viple.stop()

    asyncio.run(scenario())
    assert messages(caplog, "disconnected (workbench stopping)")


class DeafViple(FakeViple):
    """A VIPLE that accepts the robot, sends it one command (on the first connection only) and
    then reads nothing at all."""

    commanded = False

    async def start(self) -> DeafViple:
        self.arrived = asyncio.Event()
        sock = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
        sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        sock.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 1024)
        sock.bind(("127.0.0.1", self.port))
        self.server = await serve(
            self._robot, sock=sock, max_queue=1, ping_interval=None, close_timeout=0.2
        )
        return self

    async def _robot(self, ws: ServerConnection) -> None:
        self.robot = ws
        self.arrived.set()
        if not self.commanded:
            self.commanded = True
            await ws.send(MOVE)
        await ws.wait_closed()


def test_a_driver_that_stops_sending_and_reading_loses_the_seat_and_the_robot_stops(caplog):
    caplog.set_level(logging.INFO, logger="workbench.viple")

    async def scenario():
        viple = await DeafViple(free_port()).start()
        session = Session(CORRIDOR, "unity", many_sensors(), noise="off")
        async with client_for(session, viple.url, report_ms=50, idle_s=0.5) as client:
            await viple.connected()
            await until(lambda: client.status.messages_in == 1)
            await until(lambda: client.status.idled == 1, timeout=10)
            x = session.world.pose.x
            steps(session, 30)
            assert session.world.pose.x == pytest.approx(x)  # the motors were stopped at once
            # the connection itself is gone once the deaf peer's close handshake times out
            idle = "disconnected (idle: sent nothing and read no reports for 0.5 s"
            await until(lambda: messages(caplog, idle), timeout=10)
        await viple.stop()

    asyncio.run(scenario())


def test_a_viple_that_stops_answering_pings_is_left_even_without_an_idle_limit(caplog):
    caplog.set_level(logging.INFO, logger="workbench.viple")

    async def scenario():
        viple = await DeafViple(free_port()).start()
        session = session_for()
        config = {"idle_s": None, "ping_interval_s": 0.1, "ping_timeout_s": 0.3}
        async with client_for(session, viple.url, **config) as client:
            await viple.connected()
            await until(lambda: client.status.messages_in == 1)
            await until(lambda: "went away" in caplog.text, timeout=5)
            assert client.status.idled == 0
        await viple.stop()

    asyncio.run(scenario())
    assert messages(caplog, "keepalive ping timeout")


def test_pings_are_on_by_default():
    assert WsConfig().ping_interval_s == 20.0 and WsConfig().ping_timeout_s == 20.0
    assert WsConfig().idle_s == 30.0
    with pytest.raises(ValueError, match="driver idle time"):
        WsConfig(idle_s=-1)
