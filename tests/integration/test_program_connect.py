"""`workbench viple run FILE --connect`: a VIPLE program drives a robot over the protocol, at
the address its own Robot activity names, here the robot `workbench serve` plays on loopback."""

from __future__ import annotations

import json
import signal
import subprocess
import sys

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
