"""`workbench viple-client`, the VIPLE stand-in: its pieces, its bytes on the wire, and whole
runs through `workbench serve` compared with the same run in process."""

from __future__ import annotations

import asyncio
import json
import math
import signal
import socket
import subprocess
import sys
import time
from pathlib import Path

import pytest
from websockets.asyncio.client import connect as ws_connect

from tests.sessions import free_port
from workbench.cli import main
from workbench.control.headless import AlgorithmPilot, RunSpec, run
from workbench.sim.commands import MoveAtPower, Stop, TurnByDegrees
from workbench.sim.noise import noise_settings
from workbench.sim.profiles import get_profile
from workbench.viple import client as client_mod
from workbench.viple.client import (
    MAX_LAG_S,
    ClientRunError,
    ClientSetupError,
    Departures,
    Endpoint,
    RemoteFsm,
    parse_endpoint,
    prepare,
    readings_by_name,
    run_client,
    turn_wait,
)

EROBOTIC = get_profile("erobotic")
MOVE = b'{"servos":[{"isTurn":false,"servoId":-1,"servoSpeed":1}]}\r\n'
RIGHT90 = b'{"servos":[{"isTurn":true,"servoId":-1,"servoSpeed":90}]}\r\n'
STOP = (
    b'{"servos":[{"isTurn":false,"servoId":3,"servoSpeed":0},'
    b'{"isTurn":false,"servoId":5,"servoSpeed":0}]}\r\n'
)
#: the same two commands as Robot Drive wheel powers (erobotic: Move at Power 1 is full power on
#: both wheels; the spin at the 90 deg/s turn rate is half power, left wheel forward)
WHEELS_MOVE = (
    b'{"servos":[{"isTurn":false,"servoId":3,"servoSpeed":1},'
    b'{"isTurn":false,"servoId":5,"servoSpeed":1}]}\r\n'
)
WHEELS_RIGHT90 = (
    b'{"servos":[{"isTurn":false,"servoId":3,"servoSpeed":0.5},'
    b'{"isTurn":false,"servoId":5,"servoSpeed":-0.5}]}\r\n'
)


def report(front: float, port: int = 1) -> bytes:
    return b'{"sensors":[{"name":"distance","id":%d,"value":%s}]}\r\n' % (port, str(front).encode())


def local_best(**kw):
    kw.setdefault("profile", "erobotic")
    return prepare("two-distance-local-best", **kw)


# ----------------------------------------------------------------------------- pieces


def test_turn_wait_is_the_profiles_turn_time_plus_a_margin():
    assert turn_wait(90, EROBOTIC) == pytest.approx(90 / 90 * 1.1 + 0.3)
    assert turn_wait(-180, EROBOTIC) == turn_wait(180, EROBOTIC) == pytest.approx(2.5)
    unity = get_profile("unity")
    assert turn_wait(90, unity) == pytest.approx(90 / 35 * 1.1 + 0.3)


@pytest.mark.parametrize("profile", ["unity", "web", "erobotic"])
def test_turn_wait_covers_five_sigma_of_realistic_turn_noise(profile):
    prof = get_profile(profile)
    sigma = noise_settings("realistic", prof).turn_error
    for degrees in (15, 90, 180, 360):
        assert turn_wait(degrees, prof) > degrees * (1 + 5 * sigma) / prof.turn_rate + 0.2


def test_readings_by_name_follow_the_binding():
    assert readings_by_name({1: 52.0, 2: 300.0, 3: 60.0}, {"front": 1, "right": 3}) == {
        "front": 52.0,
        "right": 60.0,
    }


def test_a_report_without_a_bound_port_is_explained():
    with pytest.raises(ClientRunError) as err:
        readings_by_name({2: 1.0, 5: 0.0}, {"front": 1})
    assert "no sensor on port 1 (front); they carry port(s) 2, 5" in str(err.value)
    assert "--sensor" in str(err.value)


def test_the_fsm_turns_by_degree_and_takes_the_turn_as_done_after_the_estimate():
    fsm = RemoteFsm(local_best())
    start = fsm.start(0.0)
    assert start.started and start.commands == [MoveAtPower(1.0)]
    assert fsm.report(0.05, {1: 172.0}).commands == []
    step = fsm.report(1.0, {1: 49.0})
    assert step.transition.target == "TurningRight"
    assert step.commands == [TurnByDegrees(90.0)]
    assert step.turn_done_at == pytest.approx(1.0 + turn_wait(90, EROBOTIC))
    assert fsm.tick(2.3).transition is None  # 1.3 s: the turn is not yet taken as done
    done = fsm.tick(2.41)
    assert done.transition.source == "TurningRight" and done.commands == [Stop()]
    assert fsm.turn_due is None
    assert fsm.tick(2.46).transition.target == "TurningLeft"  # stop_wait 0: the next tick


def test_ticks_wait_for_the_first_report_and_are_due_at_the_control_rate():
    fsm = RemoteFsm(local_best())
    fsm.start(0.0)
    assert fsm.tick(0.5).commands == [] and fsm.readings is None
    assert fsm.next_tick() == pytest.approx(0.55)
    fsm.report(0.6, {1: 500.0})
    assert fsm.next_tick() == pytest.approx(0.65)


TURN_THEN_GO = """\
name: turn-then-go
sensors:
  front: {kind: distance, mount: front, port: 1}
initial: Turn
states:
  Turn:
    on_enter:
      - turn: 90
      - timer: 0.2
    transitions:
      - when: timer_done
        to: Go
  Go:
    on_enter:
      - move: 1
    transitions:
      - when: turn_done
        to: Turn
"""


def test_any_other_command_abandons_the_turn_and_its_estimate(tmp_path):
    path = tmp_path / "turn-then-go.yaml"
    path.write_text(TURN_THEN_GO)
    fsm = RemoteFsm(prepare(str(path), profile="erobotic"))
    assert fsm.start(0.0).commands == [TurnByDegrees(90.0)] and fsm.turn_due is not None
    fsm.report(0.1, {1: 500.0})
    assert fsm.tick(0.25).commands == [MoveAtPower(1.0)]
    assert fsm.turn_due is None
    assert fsm.tick(5.0).transition is None  # the abandoned turn never reports done


@pytest.mark.parametrize(
    ("connect", "listen", "expected"),
    [
        (None, None, Endpoint("connect", "localhost", 1350)),
        ("tcp://127.0.0.1:4000", None, Endpoint("connect", "127.0.0.1", 4000)),
        ("tcp://[::1]", None, Endpoint("connect", "::1", 1350)),
        (None, "ws://localhost:8124/", Endpoint("listen", "localhost", 8124)),
        (None, "ws://0.0.0.0", Endpoint("listen", "0.0.0.0", 8124)),
    ],
)
def test_endpoints(connect, listen, expected):
    assert parse_endpoint(connect, listen) == expected


def test_endpoints_print_as_urls():
    assert str(Endpoint("connect", "::1", 1350)) == "tcp://[::1]:1350"
    assert str(Endpoint("listen", "localhost", 8124)) == "ws://localhost:8124/"


@pytest.mark.parametrize(
    ("kw", "message"),
    [
        ({"connect": "localhost:1350"}, "must be tcp://HOST:PORT, e.g. tcp://localhost:1350"),
        ({"connect": "ws://localhost:1350"}, "must be tcp://HOST:PORT"),
        ({"connect": "tcp://localhost:http"}, "the port is not a number from 1 to 65535"),
        ({"connect": "tcp://localhost:70000"}, "the port is not a number from 1 to 65535"),
        ({"connect": "tcp://localhost:1350/robot"}, "nothing may follow the port"),
        ({"listen": "tcp://localhost:8124"}, "must be ws://HOST:PORT, e.g. ws://localhost:8124"),
        ({"connect": "tcp://a:1", "listen": "ws://a:2"}, "either --connect or --listen"),
    ],
)
def test_bad_endpoints_are_explained(kw, message):
    with pytest.raises(ClientSetupError, match=message.replace("(", r"\(").replace(".", r"\.")):
        parse_endpoint(**kw)


@pytest.mark.parametrize(
    ("kw", "message"),
    [
        ({"algorithm": "two-distance-best"}, "did you mean 'two-distance-local-best'?"),
        ({"sensors": ["distance:one:front"]}, "port 'one' is not a whole number"),
        ({"sensors": ["distance:1:right"]}, "needs a distance sensor mounted front"),
        ({"params": ["front_blocked=near"]}, "'near' is not a number"),
        ({"params": ["speed=1"]}, "has no parameter 'speed'"),
        ({"profile": "lego"}, "unknown profile 'lego'"),
        ({"duration": 0.0}, "--duration must be a positive number"),
    ],
)
def test_bad_set_up_is_explained(kw, message):
    kw.setdefault("algorithm", "two-distance-local-best")
    with pytest.raises(ClientSetupError, match=message):
        prepare(**kw)


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["--algorithm", "wall-right"], "no built-in algorithm or FSM file named 'wall-right'"),
        (["--algorithm", "right-wall", "--connect", "http://x"], "must be tcp://HOST:PORT"),
        (["--algorithm", "right-wall", "--sensor", "sonar:1:right"], "unknown sensor kind"),
        (["--algorithm", "right-wall", "--duration", "-3"], "positive number of seconds"),
        (["--algorithm", "missing.yaml"], "missing.yaml"),
    ],
)
def test_cli_bad_input_exits_2_without_a_traceback(capsys, argv, message):
    assert main(["viple-client", *argv]) == 2
    err = capsys.readouterr().err
    assert message in err and "Traceback" not in err


def test_cli_with_nothing_listening_retries_then_exits_1(capsys, monkeypatch, unused_port):
    monkeypatch.setattr(client_mod, "CONNECT_PATIENCE_S", 0.6)
    argv = [
        "viple-client",
        "--algorithm",
        "right-wall",
        "--connect",
        f"tcp://127.0.0.1:{unused_port}",
    ]
    assert main(argv) == 1
    captured = capsys.readouterr()
    assert "yet (connection refused, nothing listens there); retrying" in captured.out
    assert f"cannot connect to tcp://127.0.0.1:{unused_port}" in captured.err
    assert "workbench serve" in captured.err


def test_cli_listening_on_a_port_in_use_exits_1(capsys):
    with socket.socket() as taken:
        taken.bind(("127.0.0.1", 0))
        taken.listen()
        port = taken.getsockname()[1]
        argv = ["viple-client", "--algorithm", "right-wall", "--listen", f"ws://127.0.0.1:{port}"]
        assert main(argv) == 1
    err = capsys.readouterr().err
    assert f"cannot listen at ws://127.0.0.1:{port}/: port {port} is in use" in err


# ----------------------------------------------------------------------------- on the wire


@pytest.fixture
def unused_port():
    return free_port()


class ScriptedRobot:
    """A bare TCP robot: sends the given reports one by one, keeping what the client sends."""

    def __init__(self, reports: list[bytes], gap: float = 0.1) -> None:
        self.reports = reports
        self.gap = gap
        self.received = b""

    async def serve(self, reader, writer) -> None:
        async def collect():
            while data := await reader.read(4096):
                self.received += data

        collector = asyncio.create_task(collect())
        for line in self.reports:
            writer.write(line)
            await writer.drain()
            await asyncio.sleep(self.gap)
        writer.close()
        await collector

    async def run(self, **kw):
        server = await asyncio.start_server(self.serve, "127.0.0.1", 0)
        port = server.sockets[0].getsockname()[1]
        async with server:
            setup = local_best(connect=f"tcp://127.0.0.1:{port}", **kw)
            return await run_client(setup, log=lambda text: None)


def test_tcp_client_sends_viple_bytes_and_ends_when_the_robot_closes():
    robot = ScriptedRobot([report(172.0), report(49.0), report(60.0)])
    result = asyncio.run(robot.run(unity_simulator=True))
    assert robot.received.startswith(MOVE + RIGHT90)
    assert result.ended == "closed" and result.exit_code == 0
    assert result.reports == 3 and result.commands == 2 and result.final_state == "TurningRight"


def test_reports_split_across_writes_and_bad_lines_are_handled():
    robot = ScriptedRobot(
        [b'{"sensors":[{"name":"distance",', b'"id":1,"value":"172"}]}\r\nnot json\n', report(40)]
    )
    result = asyncio.run(robot.run())
    assert result.reports == 2 and result.rejected == 1
    assert robot.received == WHEELS_MOVE + WHEELS_RIGHT90


def test_hostile_report_lines_are_only_rejected_and_the_run_goes_on():
    lines: list[str] = []
    robot = ScriptedRobot(
        [
            b"[" * 60_000 + b"\r\n",
            b'{"error":"\\u001b[2Jgone"}\r\n',
            b'{"sensors":[{"id":1,"value":"\\u001e172"}]}\r\n',
            report(172.0),
        ]
    )

    async def go():
        server = await asyncio.start_server(robot.serve, "127.0.0.1", 0)
        port = server.sockets[0].getsockname()[1]
        async with server:
            return await run_client(local_best(connect=f"tcp://127.0.0.1:{port}"), lines.append)

    result = asyncio.run(go())
    assert result.reports == 1 and result.rejected == 3
    assert any("the simulator says: \\u001b[2Jgone" in x for x in lines)
    assert not any("\x1b" in x for x in lines)
    assert any(
        'sensors[0].value "\\u001e172" holds a control character (U+001E)' in x for x in lines
    )


def test_a_report_missing_the_fsm_sensor_stops_the_robot_and_exits_1():
    robot = ScriptedRobot([report(172.0, port=4)])
    result = asyncio.run(robot.run())
    assert result.ended == "error" and result.exit_code == 1
    assert "no sensor on port 1 (front)" in result.message
    assert robot.received == WHEELS_MOVE + STOP


def test_duration_ends_the_run_and_stops_the_robot():
    robot = ScriptedRobot([report(172.0)] * 20)
    result = asyncio.run(robot.run(duration=0.5))
    assert result.ended == "duration" and result.exit_code == 0
    assert result.time >= 0.5  # ended by the duration (above), not before it
    assert robot.received == WHEELS_MOVE + STOP


def test_a_refusal_is_shown_and_a_run_without_reports_exits_1():
    lines: list[str] = []
    robot = ScriptedRobot([b'{"error":"the robot already has a driver"}\r\n'])

    async def go():
        server = await asyncio.start_server(robot.serve, "127.0.0.1", 0)
        port = server.sockets[0].getsockname()[1]
        async with server:
            return await run_client(local_best(connect=f"tcp://127.0.0.1:{port}"), lines.append)

    result = asyncio.run(go())
    assert result.exit_code == 1 and result.rejected == 1
    assert any("the simulator says: the robot already has a driver" in x for x in lines)


def test_websocket_role_serves_one_simulator_and_refuses_a_second(unused_port):
    url = f"ws://127.0.0.1:{unused_port}/"

    async def simulator():
        for _ in range(50):
            try:
                ws = await ws_connect(url)
                break
            except OSError:
                await asyncio.sleep(0.05)
        async with ws:
            first = await ws.recv()
            await ws.send(report(172.0).decode().strip())
            await ws.send(report(45.0).decode())  # a frame ending in CRLF is accepted too
            second = await ws.recv()
            async with ws_connect(url) as other:
                refused = await other.wait_closed() or other.close_code
            return first, second, refused

    async def go():
        setup = local_best(listen=url, unity_simulator=True)
        client = asyncio.create_task(run_client(setup, log=lambda text: None))
        frames = await simulator()
        return frames, await client

    (first, second, refused), result = asyncio.run(go())
    assert first == MOVE.decode().strip() and second == RIGHT90.decode().strip()
    assert refused == 1013
    assert result.ended == "closed" and result.exit_code == 0 and result.reports == 2


# ----------------------------------------------------------------------------- end to end

#: a corridor with one corner: the robot drives up one block, looks right (a wall), looks left
#: (the exit) and drives out: two Turn by Degree, about 6 s of simulated time
ONE_CORNER = """\
---
name: One corner
profile: erobotic
---
####
E..#
##^#
####
"""
ALGORITHM = "two-distance-local-best"
#: how far the served run may drive beyond the in-process one: it stops at the corner up to
#: two report intervals (50 ms each: the reading's age and the push schedule) later than the
#: in-process FSM does at its control tick, and its record sees the exit at the next control
#: tick (up to 50 ms after it), all at the erobotic speed
DISTANCE_SLACK = 0.2 * EROBOTIC.move_speed


def metrics_at_exit(record: Path) -> dict:
    """Distance and turning up to the first control tick that saw the exit, from the poses of
    a run record (the served robot drives on after the exit; the in-process run stops)."""
    distance = turning = 0.0
    last = None
    for line in record.read_text().splitlines():
        tick = json.loads(line)
        if "type" in tick:
            continue
        x, y, heading = tick["pose"]
        if last is not None:
            distance += math.hypot(x - last[0], y - last[1])
            turning += abs((heading - last[2] + 180.0) % 360.0 - 180.0)
        last = (x, y, heading)
        if "exit" in tick.get("events", ()):
            return {"reached_exit": True, "distance": distance, "turn_degrees": turning}
    return {"reached_exit": False, "distance": distance, "turn_degrees": turning}


def summary_of(record: Path) -> dict:
    last = json.loads(record.read_text().splitlines()[-1])
    assert last["type"] == "summary"
    return last


def workbench(*argv: str) -> subprocess.Popen:
    return subprocess.Popen(
        [sys.executable, "-m", "workbench", *argv],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )


def wait_for_exit(record: Path, procs: list[subprocess.Popen], limit: float = 30.0) -> None:
    deadline = time.monotonic() + limit
    while time.monotonic() < deadline:
        if record.exists() and '"exit"' in record.read_text():
            return
        for proc in procs:
            assert proc.poll() is None, proc.communicate()
        time.sleep(0.1)
    pytest.fail(f"the robot did not reach the exit within {limit:g} s")


def interrupt(proc: subprocess.Popen) -> tuple[int, str, str]:
    proc.send_signal(signal.SIGINT)
    out, err = proc.communicate(timeout=15)
    return proc.returncode, out, err


def served_run(tmp_path: Path, role: str, unity: bool = True) -> tuple[dict, dict, str]:
    """The run through `workbench serve` driven by `workbench viple-client` (in the Unity
    simulator's form, else in wheel powers); its metrics at the exit, the server's summary line
    and the client's output."""
    maze = tmp_path / "one-corner.txt"
    maze.write_text(ONE_CORNER)
    record = tmp_path / f"served-{role}.jsonl"
    port = free_port()
    serve = ["serve", "--maze", str(maze), "--report-ms", "50", "--record", str(record)]
    # workbench serve plays the Unity simulator: the client can turn by Turn by Degree, as the
    # in-process run does
    client = ["viple-client", "--algorithm", ALGORITHM, "--profile", "erobotic"]
    if unity:
        client.append("--unity-simulator")
    procs: list[subprocess.Popen] = []
    try:
        if role == "tcp":
            procs.append(workbench(*serve, "--tcp-port", str(port)))
            procs.append(workbench(*client, "--connect", f"tcp://localhost:{port}"))
        else:
            procs.append(workbench(*client, "--listen", f"ws://localhost:{port}"))
            url = f"ws://localhost:{port}/"
            procs.append(workbench(*serve, "--tcp-port", "0", "--ws-url", url))
        wait_for_exit(record, procs)
        viple = procs[0] if role == "ws" else procs[1]
        code, out, err = interrupt(viple)
        assert code == 130, err
        code, _, err = interrupt(procs[0] if role == "tcp" else procs[1])
        assert code == 0, err
    finally:
        for proc in procs:
            if proc.poll() is None:
                proc.kill()
                proc.communicate()
    return metrics_at_exit(record), summary_of(record), out


@pytest.fixture(scope="module")
def in_process(tmp_path_factory) -> dict:
    folder = tmp_path_factory.mktemp("in-process")
    maze = folder / "one-corner.txt"
    maze.write_text(ONE_CORNER)
    record = folder / "run.jsonl"
    spec = RunSpec(str(maze), AlgorithmPilot(ALGORITHM), profile="erobotic", record=str(record))
    result = run(spec)
    at_exit = metrics_at_exit(record)
    assert at_exit["distance"] == pytest.approx(result.metrics["distance"], abs=1e-6)
    assert at_exit["turn_degrees"] == pytest.approx(result.metrics["turn_degrees"], abs=1e-6)
    return {**result.metrics, "final_state": result.final_state}


@pytest.mark.long
@pytest.mark.parametrize("role", ["tcp", "ws"])
def test_viple_client_drives_out_through_serve_like_the_in_process_run(tmp_path, in_process, role):
    at_exit, summary, out = served_run(tmp_path, role)
    assert in_process["reached_exit"] and in_process["turns"] == 2
    assert summary["reached_exit"] and at_exit["reached_exit"]
    assert at_exit["turn_degrees"] == pytest.approx(in_process["turn_degrees"], abs=1.0)
    assert at_exit["distance"] == pytest.approx(in_process["distance"], abs=DISTANCE_SLACK)
    assert summary["collisions"] == in_process["collisions"] == 0
    assert "TurningRight -> TurnedRight" in out and "TurnedLeft -> Forward" in out
    assert "summary:" in out and "stopped by SIGINT" in out


# ----------------------------------------------------------------------------- a robot's own


def test_the_stand_in_client_speaks_wheel_powers_to_a_robot_that_knows_only_its_wheels():
    """The robot's listener takes only Robot Drive's two wheel entries (it breaks on anything
    else); right-wall drives it, turns left at a wall and drives on, then Ctrl+C stops it."""
    from tests.integration.fake_robot import FakeRobot, collapsed, wheel_powers

    def distances(front: float, right: float) -> bytes:
        entries = [
            {"name": "distance", "id": 1, "value": front},
            {"name": "distance", "id": 3, "value": right},
        ]
        return (json.dumps({"sensors": entries}) + "\r\n").encode()

    spin = (-0.5, 0.5)  # a left turn at erobotic's 90 deg/s: half power, right wheel forward
    stop, move = (0.0, 0.0), (1.0, 1.0)
    proc: list[subprocess.Popen] = []

    def script(robot: FakeRobot) -> bytes | None:
        if robot.broken is not None:
            return None  # its listener failed: the robot hears nothing more
        seen = collapsed(robot.powers())
        if move not in seen:
            return distances(200, 60)
        if spin not in seen:
            return distances(40, 60)  # a wall ahead, none open on the right: turn left
        if seen[seen.index(spin) :][:3] == [spin, stop, move] and proc[0].poll() is None:
            proc[0].send_signal(signal.SIGINT)  # driving on after the turn: the user stops it
        return distances(200, 60)

    with FakeRobot(script, accepts=lambda message: wheel_powers(message) is not None) as robot:
        argv = ["viple-client", "--algorithm", "right-wall", "--profile", "erobotic"]
        proc.append(workbench(*argv, "--connect", robot.url, "--json"))
        try:
            out, err = proc[0].communicate(timeout=90)
        finally:
            if proc[0].poll() is None:
                proc[0].kill()
                proc[0].communicate()
    assert robot.broken is None, robot.broken
    assert proc[0].returncode == 130, err
    result = json.loads(out)
    assert result["commands"] == len(robot.commands)  # every command reached the robot...
    # ...as two wheel entries: go, the turn's spin, its end, go again, and the final stop
    assert collapsed(robot.powers()) == [move, spin, stop, move, stop]
    assert "commands as wheel powers" in err


def test_the_unity_simulator_form_is_offered_in_the_help(capsys):
    with pytest.raises(SystemExit):
        main(["viple-client", "--help"])
    text = " ".join(capsys.readouterr().out.split())
    assert "--unity-simulator send the Unity simulator's Robot+ commands" in text
    assert "Commands go as Robot Drive's two wheel powers" in text


@pytest.mark.long
def test_viple_client_in_wheel_powers_drives_out_through_serve(tmp_path, in_process):
    """The same run with every command as wheel powers: each turn is a spin the client stops
    on its own clock, so it ends within a few degrees of the Turn by Degree's angle."""
    at_exit, summary, out = served_run(tmp_path, "tcp", unity=False)
    assert summary["reached_exit"] and at_exit["reached_exit"]
    assert at_exit["turn_degrees"] == pytest.approx(in_process["turn_degrees"], abs=10.0)
    assert summary["collisions"] == 0
    assert "TurningRight -> TurnedRight" in out and "TurnedLeft -> Forward" in out


def test_commands_are_held_to_their_time_only_while_a_timer_runs():
    departures = Departures()
    departures.begin(timing=False)
    assert departures.due(0.0) == 0.0
    departures.left(0.0, 0.015)  # the first step of a pulse took 15 ms to run
    departures.begin(timing=True)  # its Timer runs: the pulse's end leaves as late
    assert departures.due(0.040) == pytest.approx(0.055)
    departures.left(0.2, 0.203)  # a quicker step later does not undo the earlier delay
    assert departures.due(0.3) == pytest.approx(0.315)
    departures.begin(timing=False)  # no timer ran: nothing to keep apart, no wait
    assert departures.due(1.0) == 1.0
    departures.left(2.0, 62.0)  # a minute's stall (a suspended process) is no step's run time
    assert departures.due(3.0) == pytest.approx(3.0 + MAX_LAG_S)
