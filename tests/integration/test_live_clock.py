"""A VIPLE program over the network drives the lab station on the real clock.

A scripted VIPLE over a real loopback TCP socket drives a :class:`LabStation` (the station is
the endpoint's seat): while it is connected the station runs at 1x whatever speed was set,
the speed cannot be changed, and a paused station holds its commands (not applied) while the
program keeps getting the robot's real readings. Time is handed to the station by the test,
so every number is deterministic.
"""

from __future__ import annotations

import asyncio
import logging

import pytest

from tests.integration.test_tcp_server import MOVE, STOP, Client
from tests.integration.test_ws_client import MOVE as WS_MOVE
from tests.integration.test_ws_client import RETRY, FakeViple
from tests.sessions import CORRIDOR, free_port
from tests.waiting import until
from workbench.control.station import LabStation
from workbench.sim.mazeio import load_maze, parse_maze
from workbench.sim.metrics import Metrics
from workbench.viple.codec import parse_report
from workbench.viple.tcp_server import TcpConfig, TcpServer
from workbench.viple.ws_client import WsClient, WsConfig


def station() -> LabStation:
    return LabStation.open(CORRIDOR, "unity", noise="off")


def test_a_connected_program_runs_the_station_at_1x_and_the_speed_is_held():
    async def scenario() -> None:
        b = station()
        assert b.set_speed(None)  # "max", left over from a run before
        async with TcpServer(b, TcpConfig(port=0)) as server:
            client = await Client.connect(server.port)
            await client.report()
            assert b.live_viple is not None and str(b.live_viple).startswith("VIPLE tcp ")
            assert b.pacer.speed == 1.0
            assert not b.next_speed() and not b.set_speed(None)  # held, nothing changed
            assert b.pacer.speed == 1.0 and not b.at_rest
            # at 1x, a tenth of a second of wall time is six steps of 1/60 s (at max it would
            # be as many as the frame's budget allows)
            assert b.advance(0.1) == 6
            await client.send(MOVE)
            await client.report()
            assert b.advance(0.2) == 12
            assert b.snapshot().metrics.sim_time == pytest.approx(0.3)
            await client.close()
            await until(lambda: b.live_viple is None, "the program let go")
            assert b.pacer.speed == 1.0  # its run is over: 1x, as after every run
            assert b.runs[-1].driver.is_viple and b.runs[-1].ended == "stopped"
            assert b.next_speed() and b.pacer.speed == 2.0  # the speed key works again

    asyncio.run(scenario())


def test_a_program_over_websocket_holds_the_speed_and_is_held_while_paused_too():
    async def scenario() -> None:
        b = station()
        b.set_speed(10.0)
        viple = await FakeViple(free_port()).start()
        config = WsConfig(url=viple.url, retry_seconds=RETRY, report_ms=1000)
        async with WsClient(b, config) as client:
            robot = await viple.connected()
            await viple.report()
            assert str(b.live_viple) == f"VIPLE ws {viple.url}" and b.pacer.speed == 1.0
            assert not b.next_speed()
            b.pause()
            await robot.send(WS_MOVE)
            await viple.report()  # answered with the readings of the robot standing
            await until(lambda: client.status.held == 1 and b.held_count == 1)
            assert b.snapshot().metrics.distance == 0
        await viple.stop()
        assert b.live_viple is None and b.pacer.speed == 1.0

    asyncio.run(scenario())


def test_a_paused_station_holds_the_commands_and_keeps_reporting_true_readings(caplog):
    async def scenario() -> None:
        b = station()
        async with TcpServer(b, TcpConfig(port=0, report_ms=1000)) as server:
            client = await Client.connect(server.port)
            await client.report()
            b.step(3)  # the readings of the robot at the start
            b.pause()
            pose = b.snapshot().pose
            standing = parse_report(server.link.report())
            assert standing[2] > 0  # the front distance sensor reads the far wall
            for n in range(1, 4):
                await client.send(MOVE)
                report = await client.report()
                assert report == standing  # the robot's real readings: it stands as it was
                await until(lambda n=n: b.held_count == n and server.status.held == n)
            assert server.status.messages_in == 3 and server.status.messages_out >= 4
            assert b.advance(1.0) == 0
            assert b.snapshot().pose == pose  # held, not applied
            held = [r.getMessage() for r in caplog.records if "held" in r.getMessage()]
            assert len(held) == 1 and "commands held, not applied" in held[0]  # once
            b.step(1)  # a single step: time runs, and the program's last command with it
            assert b.held_count == 0 and b.paused and b.snapshot().pose.x > pose.x
            await client.send(MOVE)
            await client.report()
            await until(lambda: b.held_count == 1)  # paused still: held again
            b.pause(False)  # time runs again: the program's last command is in force
            assert b.held_count == 0
            b.step(60)
            assert b.snapshot().pose.x > pose.x + 0.9
            await client.send(STOP)
            await client.report()
            again = [r.getMessage() for r in caplog.records if "applied again" in r.getMessage()]
            assert len(again) == 1
            await client.close()

    with caplog.at_level(logging.WARNING, logger="workbench.viple.tcp"):
        asyncio.run(scenario())


def test_keys_taken_while_paused_drop_what_the_program_sent():
    async def scenario() -> None:
        b = station()
        async with TcpServer(b, TcpConfig(port=0, report_ms=1000)) as server:
            client = await Client.connect(server.port)
            await client.report()
            b.pause()
            await client.send(MOVE)
            await client.report()
            assert b.held_count == 1
            b.key("space")  # the keys take the robot: stopped
            b.pause(False)
            b.step(60)
            assert b.snapshot().metrics.distance == 0
            await client.close()

    asyncio.run(scenario())


def advance_to_exit(b: LabStation) -> None:
    while not b.runs or b.runs[-1].ended != "exit":
        b.advance(1.0)  # at max: as many steps as the budget allows


def test_a_run_ends_at_1x_and_a_reset_and_a_new_maze_start_at_1x():
    b = LabStation.open(load_maze("mazes/rank-wall-wins.txt"), "unity", noise="off")
    b.select_algorithm("right-wall")
    b.apply_algorithm_preset()
    assert b.set_speed(None)
    b.start()
    assert b.pacer.speed is None  # the speed chosen before the run is the run's
    advance_to_exit(b)
    assert b.pacer.speed == 1.0  # not max after the run
    for again in (b.reset_robot, lambda: b.load_maze(CORRIDOR)):
        b.set_speed(10.0)
        again()
        assert b.pacer.speed == 1.0
    b.set_speed(4.0)
    b.key("w")  # a run by the keys, at the speed chosen
    assert b.pacer.speed == 4.0
    b.key("space")
    b.reset_robot()
    assert b.pacer.speed == 1.0


def test_a_run_gives_the_same_numbers_at_any_speed():
    def metrics(speed: float | None) -> Metrics:
        b = LabStation.open(load_maze("mazes/rank-wall-wins.txt"), "unity", noise="off")
        b.select_algorithm("right-wall")
        b.apply_algorithm_preset()
        b.set_speed(speed)
        b.start()
        advance_to_exit(b)
        return b.runs[-1].metrics

    assert metrics(None) == metrics(1.0) == metrics(4.0)


BACK = b'{"servos":[{"isTurn":false,"servoId":-1,"servoSpeed":-1}]}\r\n'
WAY_OUT = parse_maze("#########\n#S......E\n#########\n", source="way-out.txt")


def test_what_a_program_sent_to_the_robot_standing_at_the_exit_is_dropped():
    async def scenario() -> None:
        b = LabStation.open(WAY_OUT, "unity", noise="off")
        async with TcpServer(b, TcpConfig(port=0, report_ms=1000)) as server:
            client = await Client.connect(server.port)
            await client.report()
            await client.send(MOVE)
            await client.report()
            for _ in range(5000):
                if b.runs and b.runs[-1].ended == "exit":
                    break
                b.advance(0.05)
            assert b.runs[-1].ended == "exit" and b.paused  # held at the exit
            at_exit = b.snapshot().pose.x
            await client.send(BACK)  # sent to the robot standing at the exit
            await client.report()
            assert b.held_count == 1
            b.pause(False)  # p: time runs again, the run is over
            b.step(60)
            assert b.held_count == 0
            assert b.snapshot().pose.x >= at_exit  # it did not drive back into the maze
            await client.close()

    asyncio.run(scenario())
