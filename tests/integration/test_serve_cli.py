"""`workbench serve` as a user runs it: a real process, real sockets, signals, bad input."""

from __future__ import annotations

import asyncio
import json
import os
import signal
import socket
import subprocess
import sys
import time
from pathlib import Path

import pytest
from websockets.asyncio.server import serve as ws_serve

from tests.sessions import free_port
from tests.waiting import DEADLINE, until
from workbench.cli import build_parser, main
from workbench.cli.serve import plan, serve
from workbench.sim.driver import Driver
from workbench.sim.record import recorded_driver
from workbench.viple.codec import parse_report

MOVE = b'{"servos":[{"isTurn":false,"servoId":-1,"servoSpeed":1}]}\r\n'
ROOT = Path(__file__).resolve().parents[2]


def connect(port: int, timeout: float = 10.0) -> socket.socket:
    deadline = time.monotonic() + timeout
    while True:
        try:
            return socket.create_connection(("127.0.0.1", port), timeout=2.0)
        except OSError:
            if time.monotonic() > deadline:
                raise
            time.sleep(0.05)


def start_serve(*args: str) -> subprocess.Popen:
    return subprocess.Popen(
        [sys.executable, "-m", "workbench", "serve", *args],
        cwd=ROOT,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        env={**os.environ, "PYTHONUNBUFFERED": "1"},
    )


@pytest.mark.parametrize("sig", [signal.SIGINT, signal.SIGTERM])
def test_serve_is_driven_over_tcp_and_stops_cleanly_on_a_signal(tmp_path, sig):
    record = tmp_path / "run.jsonl"
    port = free_port()
    proc = start_serve(
        "--tcp-port", str(port), "--report-ms", "100", "--noise", "off", "--record", str(record)
    )
    try:
        with connect(port) as sock:
            lines = sock.makefile("rb")
            first = parse_report(lines.readline().decode())
            assert sorted(first) == [1, 2]  # the unity profile's sensors
            sock.sendall(MOVE)
            fronts = [parse_report(lines.readline().decode())[2] for _ in range(6)]
            assert fronts[-1] < fronts[0]  # driving down the first corridor, real time
        time.sleep(0.2)
        proc.send_signal(sig)
        _, err = proc.communicate(timeout=10)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.communicate()
    assert proc.returncode == 0, err
    assert "Traceback" not in err
    assert "listening for VIPLE (Unity simulator role) on 127.0.0.1:" in err
    assert "VIPLE connected from 127.0.0.1:" in err
    assert "disconnected" in err and "stopping" in err
    rows = [json.loads(line) for line in record.read_text().splitlines()]
    assert rows[0]["type"] == "header" and rows[0]["driver"] == "VIPLE"
    assert recorded_driver(rows[0]) == Driver.viple()
    summary = rows[-1]
    assert summary["type"] == "summary"
    assert summary["distance"] > 0.2
    (tcp,) = summary["endpoints"]
    assert tcp["connections"] == 1 and tcp["messages_in"] == 1 and tcp["messages_out"] >= 7


def test_serve_in_process_with_the_websocket_role_runs_in_real_time(tmp_path):
    record = tmp_path / "ws.jsonl"
    port = free_port()
    url = f"ws://127.0.0.1:{port}/"
    args = build_parser().parse_args(
        [
            *("serve", "--tcp-port", "0", "--ws-url", url, "--noise", "off"),
            *("--sensor", "distance:4:front", "touch:6:back", "--record", str(record)),
        ]
    )
    the_plan = plan(args)
    session = the_plan.session
    y0 = session.world.pose.y  # the unity maze's robot starts heading down the page (+y)
    reports: list[str] = []

    async def viple(ws):
        await ws.send(MOVE.decode())
        async for message in ws:
            reports.append(message)

    async def scenario() -> tuple[int, float]:
        stop = asyncio.Event()
        loop = asyncio.get_running_loop()
        async with ws_serve(viple, "127.0.0.1", port):
            start = loop.time()
            running = asyncio.create_task(serve(the_plan, stop))
            await until(lambda: session.world.pose.y - y0 >= 0.5, "the robot half a unit on")
            stop.set()
            code = await asyncio.wait_for(running, DEADLINE)
            return code, loop.time() - start

    t0 = session.world.time
    code, wall = asyncio.run(scenario())
    assert code == 0
    # the simulation never runs ahead of real time, and it moved at 1 unit/s of it
    simulated = session.world.time - t0
    assert simulated <= wall
    assert 0.5 <= session.world.pose.y - y0 <= simulated + 0.02
    assert str(session.driver) == "nobody"
    assert reports and all(sorted(parse_report(r)) == [4, 6] for r in reports)
    summary = json.loads(record.read_text().splitlines()[-1])
    assert summary["type"] == "summary" and summary["endpoints"][0]["role"] == "ws"


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["--maze", "no/such/maze.txt"], "cannot read"),
        (["--sensor", "distance:1"], "must be KIND:PORT:MOUNT"),
        (["--sensor", "distance:1:right", "touch:1:front"], "port 1 is used twice"),
        (["--tcp-port", "70000"], "--tcp-port 70000 is out of range"),
        (["--tcp-port", "-1"], "out of range"),
        (["--report-ms", "10"], "--report-ms: report interval 10 ms is out of range"),
        (["--report-ms", "5000"], "use 50 to 1000 ms"),
        (["--ws-url", "http://localhost:8124/"], "--ws-url: WebSocket URL"),
        (["--ws-url", "ws://localhost:99999/"], "out of range"),
        (["--tcp-port", "0"], "--tcp-port 0 turns TCP off: give --ws-url"),
        (["--tcp-port", "0", "--ws-url", "ws://x/", "--bind", "0.0.0.0"], "--bind needs TCP"),
        (["--driver-idle", "-5"], "--driver-idle -5 is not a usable time: give seconds above 0"),
        (["--driver-idle", "nan"], "--driver-idle nan is not a usable time"),
        (["--driver-idle", "inf"], "--driver-idle inf is not a usable time"),
    ],
)
def test_bad_input_is_a_clear_message_and_exit_2(capsys, argv, message):
    assert main(["serve", *argv]) == 2
    err = capsys.readouterr().err
    assert message in err and err.startswith("workbench serve: ")
    assert "Traceback" not in err


@pytest.mark.parametrize(
    "argv",
    [["--profile", "nope"], ["--report-ms", "fast"], ["--noise", "loud"], ["--driver-idle", "x"]],
)
def test_unparseable_options_exit_2(capsys, argv):
    with pytest.raises(SystemExit) as caught:
        main(["serve", *argv])
    assert caught.value.code == 2
    assert "Traceback" not in capsys.readouterr().err


def test_a_port_in_use_is_a_clear_error(capsys):
    with socket.socket() as other:
        other.bind(("127.0.0.1", 0))
        other.listen()
        port = other.getsockname()[1]
        assert main(["serve", "--tcp-port", str(port), "--bind", "127.0.0.1"]) == 1
    err = capsys.readouterr().err
    assert f"port {port} is in use" in err
    assert "stop the other simulator or choose --tcp-port" in err


def test_an_address_that_is_not_on_this_machine_is_a_clear_error(capsys):
    # 192.0.2.1 is reserved for documentation: no machine has it
    assert main(["serve", "--tcp-port", str(free_port()), "--bind", "192.0.2.1"]) == 1
    err = capsys.readouterr().err
    assert "cannot listen on 192.0.2.1 port" in err and "cannot assign requested address" in err


@pytest.mark.parametrize(
    ("argv", "idle_s"),
    [([], 30.0), (["--driver-idle", "2.5"], 2.5), (["--driver-idle", "0"], None)],
)
def test_the_driver_idle_time_reaches_both_endpoints(argv, idle_s):
    args = build_parser().parse_args(["serve", "--ws-url", "ws://localhost:8124/", *argv])
    the_plan = plan(args)
    assert the_plan.tcp.idle_s == idle_s and the_plan.ws.idle_s == idle_s
