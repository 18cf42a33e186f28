"""`workbench viple run FILE --connect`: a VIPLE program drives a robot over the protocol, at
the address its own Robot activity names, here the robot `workbench serve` plays on loopback."""

from __future__ import annotations

import json
import platform
import signal
import socket
import struct
import subprocess
import sys
import threading
import time

import pytest

from tests.integration.test_viple_client import free_port
from tests.program.builder import ProgramBuilder
from workbench.cli import main
from workbench.program.pilot import load_compiled
from workbench.program.problems import ProgramError
from workbench.program.remote import RemoteProgram, robot_settings, wheel_ports

CORRIDOR = """\
---
name: Corridor
profile: unity
---
#####
#...#
#.#.#
#.#.#
#^#.#
#####
"""


def approach(tmp_path, host: str, port: str, conn: str = "WiFi") -> str:
    """Forward at full power from the start; the front sensor (port 2) is printed and, under
    one unit, stops the robot and prints "near"."""
    b = ProgramBuilder()
    main_ = b.panel("Main")
    main_.add(19, host, port, conn, "3000")
    start = main_.add(3, "1")
    main_.chain(start, main_.add(20, "value", "value", "Robot/IoT Controller 0", "3", "5"))
    front = main_.add(23, "Robot/IoT Controller 0", "2")
    near = main_.add(6, "value < 1")
    stop = main_.add(20, "0", "0", "Robot/IoT Controller 0", "3", "5")
    said = main_.add(2, '"near " + value')
    main_.chain(front, near, stop, said, main_.add(28, ""))
    return b.write(tmp_path / "approach.viple")


def test_the_robot_activity_names_the_endpoint_and_drive_the_wheel_ports(tmp_path):
    compiled = load_compiled(approach(tmp_path, "10.0.0.1", "8124"))
    assert robot_settings(compiled).url == "tcp://10.0.0.1:8124"
    assert wheel_ports(compiled) == (3, 5)
    compiled = load_compiled(approach(tmp_path, "", "8124", "WSS"))
    assert robot_settings(compiled).url == "ws://localhost:8124/"
    with pytest.raises(ProgramError, match="is not WiFi or WSS"):
        robot_settings(load_compiled(approach(tmp_path, "x", "1", "Bluetooth")))
    with pytest.raises(ProgramError, match="not a number from 1 to 65535"):
        robot_settings(load_compiled(approach(tmp_path, "x", "99999")))


def test_a_remote_program_fires_sensors_on_reports_only():
    from workbench.program.compiled import compile_program
    from workbench.program.loader import load_program_text

    b = ProgramBuilder()
    panel = b.panel("Main")
    b.robot(panel)
    panel.chain(panel.add(23, "R", "2"), panel.add(28, ""))
    remote = RemoteProgram(compile_program(load_program_text(b.xml(), "t.viple")))
    remote.start(0.0)
    remote.report(0.1, {2: 4.5})
    remote.tick(0.15)
    remote.tick(0.2)
    remote.report(0.3, {2: 4.0})
    printed, _ = remote.news()
    assert [p.text for p in printed] == ["4.5", "4"]
    assert remote.missing_ports({1: 0.0}) == [2]


def test_a_program_drives_the_served_robot_and_reads_its_sensors(tmp_path, capsys):
    maze = tmp_path / "corridor.txt"
    maze.write_text(CORRIDOR)
    record = tmp_path / "served.jsonl"
    port = free_port()
    program = approach(tmp_path, "127.0.0.1", str(port))
    serve = subprocess.Popen(
        [sys.executable, "-m", "workbench", "serve", "--maze", str(maze), "--tcp-port",
         str(port), "--report-ms", "50", "--record", str(record), "--noise", "off"],
        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
    )  # fmt: skip
    try:
        # the robot is within a unit of the wall after about 5.5 s, counted from the program's
        # start (which includes waiting for the server): 8 s leave a margin on a busy machine
        code = main(["viple", "run", program, "--connect", "--duration", "8", "--json"])
    finally:
        serve.send_signal(signal.SIGINT)
        serve.communicate(timeout=15)
    captured = capsys.readouterr()
    assert code == 0, captured.err
    data = json.loads(captured.out)
    assert data["endpoint"] == f"tcp://127.0.0.1:{port}" and data["ended"] == "duration"
    assert data["reports"] > 50 and data["commands"] >= 3  # go, stop, and the final stop
    assert len(data["program_sha256"]) == 64
    assert "print: near 0.9" in captured.err or "print: near 0.8" in captured.err
    ticks = [json.loads(line) for line in record.read_text().splitlines()]
    poses = [t["pose"] for t in ticks if "pose" in t]
    travelled = abs(poses[-1][1] - poses[0][1])
    assert travelled > 2.0  # the program drove the robot up the corridor...
    summary = ticks[-1]
    assert summary["collisions"] == 0  # ...and stopped it by its front sensor, short of the wall


def test_connect_problems_are_explained(tmp_path, capsys):
    b = ProgramBuilder()
    b.panel("Main").add(3, "1")
    no_robot = b.write(tmp_path / "nobot.viple")
    assert main(["viple", "run", no_robot, "--connect"]) == 2
    assert "names no robot to connect to" in capsys.readouterr().err
    assert main(["viple", "run", no_robot, "--connect", "http://x:1"]) == 2
    assert "must be tcp://HOST:PORT" in capsys.readouterr().err
    assert main(["viple", "run", no_robot]) == 2
    assert "give --maze" in capsys.readouterr().err


# -- the wire's clock: a step's commands leave when its timers say ---------------------------

#: Linux's SO_TIMESTAMPNS (asm-generic): the kernel stamps each segment as it is received,
#: so the robot below knows when a command arrived even when its thread reads late
_SO_TIMESTAMPNS = (
    35 if sys.platform == "linux" and platform.machine() in ("x86_64", "aarch64") else None
)


class FakeRobot:
    """A robot on a real loopback socket: it writes down each command line and when it arrived
    (the kernel's receive time where it gives one, else when the line was read)."""

    def __init__(self) -> None:
        self.server = socket.create_server(("127.0.0.1", 0))
        if _SO_TIMESTAMPNS is not None:
            self.server.setsockopt(socket.SOL_SOCKET, _SO_TIMESTAMPNS, 1)  # accepted: inherited
        self.port = self.server.getsockname()[1]
        self.arrivals: list[tuple[float, dict]] = []
        self.thread = threading.Thread(target=self._serve, daemon=True)
        self.thread.start()

    def _serve(self) -> None:
        conn, _ = self.server.accept()
        pending = b""
        with conn:
            while True:
                data, ancillary, _, _ = conn.recvmsg(65536, socket.CMSG_SPACE(16))
                when = time.time()
                if not data:
                    return
                for level, kind, raw in ancillary:
                    if level == socket.SOL_SOCKET and kind == _SO_TIMESTAMPNS:
                        seconds, nanoseconds = struct.unpack("qq", raw[:16])
                        when = seconds + nanoseconds / 1e9
                *lines, pending = (pending + data).split(b"\r\n")
                self.arrivals.extend((when, json.loads(line)) for line in lines)

    def close(self) -> None:
        self.thread.join(timeout=30)
        self.server.close()


def pulse_program(tmp_path) -> str:
    """Forward for 40 ms by a Timer, then stop; beside it, the same start runs a counting loop
    of some 2,000 activities, each count a long sum (a busy step: its commands can leave only
    once it has run), and a Calculate that fails (a run-time error)."""
    b = ProgramBuilder()
    b.var("n")
    m = b.panel("Main")
    m.add(19, "127.0.0.1", "1", "WiFi", "3000")
    robot = "Robot/IoT Controller 0"
    m.chain(m.add(3, "1"), m.add(20, "0.5", "0.5", robot, "3", "5"), m.add(3, "40"),
            m.add(15, ""), m.add(20, "0", "0", robot, "3", "5"))  # fmt: skip
    merge, count = m.add(5), m.add(6, "state.n < 500")
    slow_plus_one = "value" + " + 1 - 1" * 15 + " + 1"  # some 60 tokens to work through
    m.chain(m.add(3, "0"), merge, m.add(1, "n"), count, m.add(2, slow_plus_one), merge)
    m.chain(m.add(3, '"text"'), m.add(2, "value * 2"), m.add(28, ""))
    return b.write(tmp_path / "pulse.viple")


def _powers(command: dict) -> tuple[float, float]:
    speeds = {s["servoId"]: s["servoSpeed"] for s in command["servos"]}
    return speeds[3], speeds[5]


def test_a_timed_pulse_keeps_its_length_on_the_wire(tmp_path, capsys):
    robot = FakeRobot()
    try:
        args = ["viple", "run", pulse_program(tmp_path), "--connect"]
        args += [f"tcp://127.0.0.1:{robot.port}", "--duration", "0.5", "--json", "--no-keyboard"]
        code = main(args)
    finally:
        robot.close()
    captured = capsys.readouterr()
    assert code == 0, captured.err
    commands = [_powers(c) for _, c in robot.arrivals]
    assert commands == [(0.5, 0.5), (0.0, 0.0), (0.0, 0.0)]  # go, stop, and the final stop
    (go, _), (stop, _) = robot.arrivals[:2]
    # the stop comes no sooner than the program's 40 ms after the go, however long the busy
    # start took to run (a loaded machine only makes it later)
    assert stop - go >= 0.040
    data = json.loads(captured.out)
    assert data["errors"] == 1 and data["stopped"] is None
    assert "cannot" in captured.err or "needs numbers" in captured.err  # the error was shown
    assert data["profile"] is None  # a robot over the wire is no simulated profile
