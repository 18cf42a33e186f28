"""The Unity-simulator role over real loopback sockets, with byte-exact VIPLE messages.

The simulation is stepped by the test (``session.step``) between messages, so every number
is deterministic; the server only carries messages.
"""

from __future__ import annotations

import asyncio
import contextlib
import itertools
import json
import logging
import math
import socket

import pytest

from tests.sessions import (
    CORRIDOR,
    ROOM,
    many_sensors,
    pushes_keep_their_interval,
    session_for,
    steps,
)
from tests.waiting import until
from workbench.sim.sensors import SensorSpec
from workbench.sim.session import Session
from workbench.viple.codec import parse_report
from workbench.viple.hosting import describe
from workbench.viple.link import Link, RateLimitedLog, check_report_ms
from workbench.viple.sockets import configure_socket
from workbench.viple.tcp_server import EndpointError, TcpConfig, TcpServer

MOVE = b'{"servos":[{"isTurn":false,"servoId":-1,"servoSpeed":1}]}\r\n'
MOVE_TEXT = b'{"servos":[{"isTurn":false,"servoId":-1,"servoSpeed":"0.5"}]}\r\n'
STOP = b'{"servos":[{"isTurn":false,"servoId":-1,"servoSpeed":0}]}\r\n'
TURN_90 = b'{"servos":[{"isTurn":true,"servoId":-1,"servoSpeed":90}]}\r\n'
DRIVE = (
    b'{"servos":[{"isTurn":false,"servoId":3,"servoSpeed":0.5},'
    b'{"isTurn":false,"servoId":5,"servoSpeed":0.5}]}\r\n'
)


class Client:
    """A scripted VIPLE: raw bytes out, report lines in."""

    def __init__(self, reader: asyncio.StreamReader, writer: asyncio.StreamWriter) -> None:
        self.reader = reader
        self.writer = writer

    @classmethod
    async def connect(cls, port: int, host: str = "127.0.0.1") -> Client:
        reader, writer = await asyncio.open_connection(host, port)
        return cls(reader, writer)

    async def send(self, data: bytes) -> None:
        self.writer.write(data)
        await self.writer.drain()

    async def line(self, timeout: float = 2.0) -> bytes:
        return await asyncio.wait_for(self.reader.readline(), timeout)

    async def report(self, timeout: float = 2.0) -> dict[int, float]:
        raw = await self.line(timeout)
        assert raw.endswith(b"\r\n"), raw
        return parse_report(raw.decode())

    async def skip_reports(self) -> None:
        """Drop the reports already received."""
        await asyncio.sleep(0.02)
        while True:
            try:
                await asyncio.wait_for(self.reader.readline(), 0.001)
            except TimeoutError:
                return

    async def close(self) -> None:
        self.writer.close()
        with contextlib.suppress(OSError):
            await self.writer.wait_closed()


def serve(session: Session, **config) -> TcpServer:
    return TcpServer(session, TcpConfig(port=0, **config))


def test_reports_carry_every_configured_port_and_commands_move_the_robot():
    async def scenario():
        session = session_for()
        async with serve(session) as server:
            client = await Client.connect(server.port)
            first = await client.line()
            assert first.endswith(b"\r\n")
            message = json.loads(first)
            assert [e["id"] for e in message["sensors"]] == [1, 2]
            assert {e["name"] for e in message["sensors"]} == {"distance"}
            await client.send(MOVE_TEXT)  # servoSpeed as a string
            await client.report()
            assert str(session.driver).startswith("VIPLE tcp 127.0.0.1:")
            x0 = session.world.pose.x
            steps(session, 60)
            # unity: Move at Power goes 1 unit/s whatever the power's size
            assert session.world.pose.x - x0 == pytest.approx(1.0, abs=0.02)
            await client.close()

    asyncio.run(scenario())


def test_split_lines_and_several_lines_in_one_write_are_all_applied():
    async def scenario():
        session = session_for(profile="web")
        async with serve(session) as server:
            client = await Client.connect(server.port)
            await client.report()
            reads = 0

            def heard() -> None:  # the server read bytes from the program
                nonlocal reads
                reads += 1

            server.link.heard = heard  # type: ignore[method-assign]
            await client.send(DRIVE[:20])
            await until(lambda: reads == 1, "the first part read")
            assert server.status.messages_in == 0  # half a line is not a message yet
            await client.send(DRIVE[20:] + STOP.replace(b"\r\n", b"\n") + DRIVE)
            await until(lambda: server.status.messages_in == 3)
            assert server.status.invalid == 0
            x0 = session.world.pose.x
            steps(session, 60)
            # web: (0.5, 0.5) is 70 px/s
            assert session.world.pose.x - x0 == pytest.approx(70.0, abs=1.0)
            await client.close()

    asyncio.run(scenario())


def test_each_command_line_is_answered_with_a_report_at_once():
    async def scenario():
        session = session_for()
        async with serve(session, report_ms=1000) as server:
            client = await Client.connect(server.port)
            await client.report()  # the one pushed on connect
            for _ in range(3):
                await client.send(STOP)
                await client.report(timeout=0.5)  # long before the next push
            assert server.status.messages_out == 4
            await client.close()

    asyncio.run(scenario())


def test_turn_by_degree_90_turns_the_robot_90_degrees_clockwise():
    async def scenario():
        session = session_for(ROOM)
        async with serve(session) as server:
            client = await Client.connect(server.port)
            await client.report()
            heading0 = session.world.pose.heading
            await client.send(TURN_90)
            await client.report()
            steps(session, 240)  # 90 degrees at 35 deg/s takes 2.6 s
            turned = (session.world.pose.heading - heading0) % 360
            assert turned == pytest.approx(90.0, abs=0.01)
            assert not session.world.turning
            await client.close()

    asyncio.run(scenario())


def test_front_distance_falls_while_driving_toward_a_wall():
    async def scenario():
        session = session_for()
        async with serve(session) as server:
            client = await Client.connect(server.port)
            start = await client.report()
            await client.send(MOVE)
            await client.report()
            fronts = [start[2]]
            for _ in range(5):
                steps(session, 30)
                await client.send(MOVE)
                fronts.append((await client.report())[2])
            assert all(b < a for a, b in itertools.pairwise(fronts))
            assert fronts[0] - fronts[-1] == pytest.approx(2.5, abs=0.1)
            await client.close()

    asyncio.run(scenario())


def test_disconnect_stops_the_motors_and_the_next_client_is_served():
    async def scenario():
        session = session_for()
        async with serve(session) as server:
            first = await Client.connect(server.port)
            await first.report()
            await first.send(MOVE)
            await first.report()
            await first.close()
            await until(lambda: not server.status.connected)
            assert str(session.driver) == "nobody"
            x = session.world.pose.x
            steps(session, 30)
            assert session.world.pose.x == pytest.approx(x)

            second = await Client.connect(server.port, host="::1")
            await second.report()
            await second.send(MOVE)
            await second.report()
            steps(session, 30)
            assert session.world.pose.x == pytest.approx(x + 0.5, abs=0.02)
            assert str(session.driver).startswith("VIPLE tcp [::1]:")
            assert server.status.connections == 2
            await second.close()

    asyncio.run(scenario())


def test_a_second_client_is_refused_with_a_json_error_and_the_refusal_logged(caplog):
    caplog.set_level(logging.INFO, logger="workbench.viple")

    async def scenario():
        session = session_for()
        async with serve(session) as server:
            first = await Client.connect(server.port)
            await first.report()
            intruder = await Client.connect(server.port)
            error = json.loads(await intruder.line())
            assert error["error"].startswith(
                "busy: another VIPLE program is driving this robot (from 127.0.0.1:"
            )
            assert await intruder.reader.read() == b""  # closed
            await intruder.close()
            assert server.status.refused == 1
            # the first program still drives
            await first.skip_reports()
            await first.send(MOVE)
            await first.report()
            assert str(session.driver).startswith("VIPLE tcp 127.0.0.1:")
            await first.close()

    asyncio.run(scenario())
    refusals = [r for r in caplog.records if "refused" in r.getMessage()]
    assert len(refusals) == 1 and "already driving" in refusals[0].getMessage()


def test_a_thousand_malformed_lines_are_counted_logged_sparingly_and_then_a_valid_one_works(
    caplog,
):
    caplog.set_level(logging.INFO, logger="workbench.viple")

    async def scenario():
        session = session_for()
        async with serve(session) as server:
            client = await Client.connect(server.port)
            await client.report()
            bad = [
                b"not json",
                b'{"servos":[{"servoId":3,"servoSpeed":"fast"}]}',
                b'{"servos":[]}',
                b"[1,2,3]",
                b'{"servo":1}',
                b"\xff\xfe",
                b'{"servos":[{"isTurn":"maybe","servoId":-1,"servoSpeed":1}]}',
            ]
            payload = b"\r\n".join(bad[i % len(bad)] for i in range(1000)) + b"\r\n"
            await client.send(payload)
            await client.send(MOVE)
            await until(lambda: server.status.messages_in == 1001)
            assert server.status.invalid == 1000
            assert server.status.connected
            assert server.status.last_rejection.startswith("line ")
            x = session.world.pose.x
            steps(session, 30)
            assert session.world.pose.x == pytest.approx(x + 0.5, abs=0.02)
            await client.close()
            await until(lambda: not server.status.connected)

    asyncio.run(scenario())
    rejected = [r for r in caplog.records if "rejected" in r.getMessage()]
    assert 1 <= len(rejected) <= 10
    assert any("more invalid messages" in r.getMessage() for r in caplog.records)
    assert any(
        'line 2: servos[0].servoSpeed "fast" is not a number' in r.getMessage() for r in rejected
    )


def test_an_oversized_line_is_rejected_and_skipped_and_the_connection_goes_on(caplog):
    caplog.set_level(logging.INFO, logger="workbench.viple")

    async def scenario():
        session = session_for()
        async with serve(session) as server:
            hog = await Client.connect(server.port)
            await hog.report()
            # a megabyte without a line end, sent in pieces, then its end and a good line
            for _ in range(16):
                await hog.send(b'{"servos":[' + b" " * 65_536)
            await until(lambda: server.status.invalid == 1)
            assert "longer than the limit of 65536 bytes" in server.status.last_rejection
            assert server.status.connected
            await hog.send(b"]}\r\n" + MOVE)
            await until(lambda: server.status.messages_in == 2)
            assert server.status.invalid == 1
            assert str(session.driver).startswith("VIPLE tcp 127.0.0.1:")
            x = session.world.pose.x
            steps(session, 30)
            assert session.world.pose.x == pytest.approx(x + 0.5, abs=0.02)
            await hog.close()
            await until(lambda: not server.status.connected)

    asyncio.run(scenario())
    assert any("longer than the limit of 65536 bytes" in r.getMessage() for r in caplog.records)


@pytest.mark.parametrize("report_ms", [50, 100])
def test_reports_are_pushed_at_the_configured_interval_and_never_early(report_ms):
    # how regular the pushes are on a quiet machine: bench/tcp_flood.py
    async def scenario():
        session = session_for()
        async with serve(session, report_ms=report_ms) as server:
            loop = asyncio.get_running_loop()
            start = loop.time()
            client = await Client.connect(server.port)
            await pushes_keep_their_interval(
                lambda: client.report(timeout=20), loop.time, start, report_ms / 1000, count=6
            )
            await client.close()

    asyncio.run(scenario())


def test_a_flood_of_commands_does_not_starve_the_loop_or_the_report_timer():
    async def scenario():
        session = session_for(ROOM)
        async with serve(session, report_ms=50) as server:
            client = await Client.connect(server.port)
            await client.report()
            seen: list[int] = []  # the commands taken so far, at each turn of another task

            async def ticker():
                while True:
                    await asyncio.sleep(0.005)
                    seen.append(server.status.messages_in)

            lines = 0

            async def reader():
                nonlocal lines
                while await client.reader.readline():
                    lines += 1

            tick_task = asyncio.create_task(ticker())
            read_task = asyncio.create_task(reader())
            flood = STOP * 2000
            for _ in range(10):
                await client.send(flood)
            await until(lambda: server.status.messages_in == 20_000, "the flood taken")
            # the other task had turns all through the flood, not only before and after it
            # (how many turns it gets, measured: bench/tcp_flood.py)
            during = {n for n in seen if 0 < n < 20_000}
            assert len(during) >= 3, sorted(during)
            # replies plus periodic pushes, but for any dropped while the client fell behind
            await until(lambda: lines + server.status.dropped >= 20_000)
            tick_task.cancel()
            read_task.cancel()
            await client.close()

    asyncio.run(scenario())


def test_the_same_port_on_both_loopback_addresses_and_a_port_in_use_is_a_clear_error():
    async def scenario():
        session = session_for()
        async with serve(session) as server:
            hosts = {host for host, _ in server.addresses}
            assert "127.0.0.1" in hosts
            assert {port for _, port in server.addresses} == {server.port}
            other = TcpServer(session, TcpConfig(port=server.port))
            with pytest.raises(EndpointError) as caught:
                await other.start()
            assert f"port {server.port} is in use" in str(caught.value)
            assert "stop the other simulator or choose --tcp-port" in str(caught.value)

    asyncio.run(scenario())


def test_explicit_bind_addresses_replace_the_loopback_pair():
    async def scenario():
        session = session_for()
        async with TcpServer(session, TcpConfig(port=0, bind=("127.0.0.1",))) as server:
            assert [host for host, _ in server.addresses] == ["127.0.0.1"]
            assert server.status.address == f"127.0.0.1:{server.port}"
            client = await Client.connect(server.port)
            assert (await client.line()).startswith(b'{"sensors":')
            await client.close()

    asyncio.run(scenario())


def test_report_interval_and_port_are_checked():
    for bad in (49, 1001, 250.0, True):
        with pytest.raises(ValueError, match="report interval"):
            check_report_ms(bad)
    assert check_report_ms(50) == 50 and check_report_ms(1000) == 1000
    with pytest.raises(ValueError, match="out of range"):
        TcpConfig(port=70000)


def test_rate_limited_log_holds_back_repeats_and_says_how_many(caplog):
    now = [0.0]
    limited = RateLimitedLog(logging.getLogger("test.limited"), burst=3, period=10.0)
    limited.clock = lambda: now[0]
    with caplog.at_level(logging.WARNING, logger="test.limited"):
        for _ in range(50):
            limited.warning("bad %d", 1)
        now[0] = 11.0
        limited.warning("bad %d", 2)
    messages = [r.getMessage() for r in caplog.records]
    assert messages == [
        "bad 1",
        "bad 1",
        "bad 1",
        "... and 47 more invalid messages not logged one by one",
        "bad 2",
    ]


def test_reports_follow_the_session_sensor_configuration():
    session = session_for()
    link = Link(session, "tcp")
    session.set_sensors([SensorSpec("touch", 7, "front"), SensorSpec("distance", 4, "left")])
    report = json.loads(link.report())
    assert [(e["name"], e["id"]) for e in report["sensors"]] == [("distance", 4), ("touch", 7)]
    assert report["sensors"][1]["value"] in (0, 1)
    assert math.isfinite(report["sensors"][0]["value"])


def test_report_ids_are_the_ports_configured_for_the_session():
    async def scenario():
        sensors = [SensorSpec("touch", 9, "front"), SensorSpec("distance", 4, "left")]
        session = Session(ROOM, "web", sensors, noise="off")
        async with serve(session) as server:
            client = await Client.connect(server.port)
            message = json.loads(await client.line())
            assert [(e["name"], e["id"]) for e in message["sensors"]] == [
                ("distance", 4),
                ("touch", 9),
            ]
            assert message["sensors"][1]["value"] == 0
            await client.close()

    asyncio.run(scenario())


# --- hostile and vanished drivers ------------------------------------------------------------

CONTROL_CHARACTER_LINE = b'{"servos":[{"servoId":3,"servoSpeed":"\\u001e0.5"}]}\r\n'


def test_a_number_with_a_control_character_is_rejected_and_the_same_connection_then_drives(
    caplog,
):
    caplog.set_level(logging.INFO, logger="workbench.viple")

    async def scenario():
        session = session_for()
        async with serve(session) as server:
            client = await Client.connect(server.port)
            await client.report()
            await client.send(CONTROL_CHARACTER_LINE + MOVE)
            await until(lambda: server.status.messages_in == 2)
            assert server.status.invalid == 1 and server.status.connected
            x = session.world.pose.x
            steps(session, 30)
            assert session.world.pose.x == pytest.approx(x + 0.5, abs=0.02)
            await client.close()
            await until(lambda: not server.status.connected)

    asyncio.run(scenario())
    logged = [r.getMessage() for r in caplog.records]
    assert any(
        'rejected line 1: servos[0].servoSpeed "\\u001e0.5" is not a number' in m for m in logged
    )
    assert any(m.endswith("disconnected (closed by VIPLE); motors stopped") for m in logged)
    assert not any(r.exc_info for r in caplog.records)


def test_stopping_the_server_under_a_driver_says_so(caplog):
    caplog.set_level(logging.INFO, logger="workbench.viple")

    async def scenario():
        session = session_for()
        async with serve(session) as server:
            client = await Client.connect(server.port)
            await client.report()
        assert str(session.driver) == "nobody"
        await client.close()

    asyncio.run(scenario())
    assert any("disconnected (server stopping)" in r.getMessage() for r in caplog.records)


async def not_reading_client(port: int) -> tuple[asyncio.StreamReader, asyncio.StreamWriter]:
    """A connection that reads nothing: tiny receive buffers, and a reader that is never read."""
    sock = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
    sock.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 1024)
    sock.setblocking(False)
    await asyncio.get_running_loop().sock_connect(sock, ("127.0.0.1", port))
    return await asyncio.open_connection(sock=sock, limit=256)


async def read_everything(reader: asyncio.StreamReader) -> None:
    while await reader.read(65536):
        pass


def test_a_driver_that_stops_sending_and_reading_loses_the_seat_and_the_robot_stops(caplog):
    caplog.set_level(logging.INFO, logger="workbench.viple")

    async def scenario():
        session = Session(CORRIDOR, "unity", many_sensors(), noise="off")
        async with serve(session, report_ms=50, idle_s=0.5) as server:
            _, writer = await not_reading_client(server.port)
            writer.write(MOVE)
            await until(lambda: str(session.driver).startswith("VIPLE tcp"))
            await until(lambda: not server.status.connected, timeout=20)
            assert server.status.idled == 1
            assert describe(server.status).endswith(", 1 idle driver cut off")
            assert str(session.driver) == "nobody"
            x = session.world.pose.x
            steps(session, 30)
            assert session.world.pose.x == pytest.approx(x)
            writer.close()

            # the seat is free for the next program
            client = await Client.connect(server.port)
            await client.report()
            await client.send(MOVE)
            await client.report()
            assert str(session.driver).startswith("VIPLE tcp")
            await client.close()

    asyncio.run(scenario())
    assert any(
        "disconnected (idle: sent nothing and read no reports for 0.5 s" in r.getMessage()
        for r in caplog.records
    )


def test_a_quiet_driver_that_reads_its_reports_keeps_the_seat_past_the_idle_time():
    async def scenario():
        session = session_for()
        async with serve(session, report_ms=50, idle_s=0.3) as server:
            client = await Client.connect(server.port)
            await client.send(MOVE)
            for _ in range(30):  # thirty pushes 50 ms apart: five idle times, sending nothing
                await client.report(timeout=20)
            assert server.status.connected and server.status.idled == 0
            assert str(session.driver).startswith("VIPLE tcp")
            await client.close()

    asyncio.run(scenario())


def test_reports_a_driver_does_not_read_are_dropped_not_queued():
    async def scenario():
        session = Session(CORRIDOR, "unity", many_sensors(), noise="off")
        async with serve(session, report_ms=50, idle_s=None) as server:
            reader, writer = await not_reading_client(server.port)
            writer.write(MOVE)
            await until(lambda: server.status.dropped >= 10, timeout=10)
            # what waits for the program is bounded by the limit plus one report
            sent, dropped = server.status.messages_out, server.status.dropped
            await until(lambda: server.status.dropped >= dropped + 5, "five more pushes dropped")
            assert server.status.messages_out == sent
            assert server.status.connected  # no idle limit: the seat is kept
            # a program that reads again gets fresh reports
            draining = asyncio.create_task(read_everything(reader))
            await until(lambda: server.status.messages_out > sent, timeout=5)
            writer.close()
            await asyncio.gather(draining, return_exceptions=True)

    asyncio.run(scenario())


def test_accepted_sockets_have_tcp_keepalive_on_and_a_small_send_buffer():
    with (
        socket.create_server(("127.0.0.1", 0)) as listener,
        socket.create_connection(listener.getsockname()),
        listener.accept()[0] as sock,
    ):
        configure_socket(sock)
        assert sock.getsockopt(socket.SOL_SOCKET, socket.SO_SNDBUF) <= 2 * 16384
        assert sock.getsockopt(socket.SOL_SOCKET, socket.SO_KEEPALIVE) == 1
        if hasattr(socket, "TCP_KEEPIDLE"):
            assert sock.getsockopt(socket.IPPROTO_TCP, socket.TCP_KEEPIDLE) == 30
            assert sock.getsockopt(socket.IPPROTO_TCP, socket.TCP_KEEPINTVL) == 10
            assert sock.getsockopt(socket.IPPROTO_TCP, socket.TCP_KEEPCNT) == 3


def test_the_idle_time_is_checked():
    with pytest.raises(ValueError, match="driver idle time must be a number of seconds above 0"):
        TcpConfig(idle_s=0)
    with pytest.raises(ValueError, match="finite"):
        TcpConfig(idle_s=float("inf"))
    assert TcpConfig(idle_s=None).idle_s is None


class FakeOutbox:
    """An outbox whose backlog the test sets: 0 means the program reads everything."""

    def __init__(self, backlog: int = 0) -> None:
        self.backlog = backlog
        self.lines: list[str] = []

    def queued(self) -> int:
        return self.backlog

    async def write(self, line: str) -> None:
        self.lines.append(line)


class SendingOutbox(FakeOutbox):
    """A program that sends something just before each push (while ``sending``)."""

    def __init__(self, link: Link, backlog: int) -> None:
        super().__init__(backlog)
        self.link = link
        self.sending = True

    def queued(self) -> int:
        if self.sending:
            self.link.heard()
        return super().queued()


def test_the_idle_rule_needs_both_silence_and_unread_reports():
    async def scenario():
        link = Link(session_for(), "tcp", idle_s=0.1)
        assert link.connect("127.0.0.1:5000")
        reading = FakeOutbox(backlog=0)
        pusher = asyncio.create_task(link.push_reports(reading, 0.02))
        # twenty pushes 20 ms apart, four idle times: silent, but reading, it keeps the seat
        await until(lambda: len(reading.lines) >= 20, "twenty reports read")
        assert not pusher.done() and link.idled == 0

        stuck = SendingOutbox(link, backlog=100_000)
        pusher.cancel()
        await asyncio.gather(pusher, return_exceptions=True)
        pusher = asyncio.create_task(link.push_reports(stuck, 0.02))
        # not reading, but sending before every push: keeps the seat
        await until(lambda: link.dropped >= 10, "ten pushes dropped")
        assert not pusher.done()
        assert stuck.lines == []  # nothing queued for it
        stuck.sending = False
        reason = await asyncio.wait_for(pusher, 20)  # silent and not reading
        assert reason.startswith("idle: sent nothing and read no reports for 0.1 s")
        assert link.idled == 1

    asyncio.run(scenario())
