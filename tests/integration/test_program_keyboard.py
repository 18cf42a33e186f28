"""`workbench viple run FILE --connect` at a terminal: the keys typed drive the robot through
the program's Key Press events, live. A real pseudo-terminal stands in for the student's, and
the robot is the one `workbench serve` plays on loopback."""

from __future__ import annotations

import json
import os
import re
import select
import signal
import subprocess
import sys
import termios
import time

import pytest

from tests.integration.test_program_connect import CORRIDOR
from tests.integration.test_viple_client import free_port
from tests.program.builder import ProgramBuilder
from tests.waiting import wait_until
from workbench.program.keys import RELEASE_GAP

ROBOT = "Robot/IoT Controller 0"


def drive_by_wire(tmp_path, port: int) -> str:
    """w: both wheels at 0.6 and "going"; the keyboard released: both wheels at 0."""
    b = ProgramBuilder()
    main = b.panel("Main")
    main.add(19, "127.0.0.1", str(port), "WiFi", "3000")
    w = main.add(13, "22")
    main.chain(
        w,
        main.add(20, "0.6", "0.6", ROBOT, "3", "5"),
        main.add(2, '"going"'),
        main.add(28, ""),
    )
    main.chain(main.add(29, ""), main.add(20, "0", "0", ROBOT, "3", "5"))
    return b.write(tmp_path / "wire.viple")


class Terminal:
    """The student's terminal: the program runs on its far side, the test types and reads."""

    def __init__(self) -> None:
        self.master, self.slave = os.openpty()
        self.seen = b""

    def read_until(self, text: str, timeout: float = 10.0) -> str:
        deadline = time.monotonic() + timeout
        while text.encode() not in self.seen:
            left = deadline - time.monotonic()
            if left <= 0:
                raise AssertionError(f"{text!r} not shown; the terminal shows:\n{self.shown}")
            ready, _, _ = select.select([self.master], [], [], left)
            if ready:
                try:
                    self.seen += os.read(self.master, 4096)
                except OSError:  # the far side closed
                    raise AssertionError(f"{text!r} not shown:\n{self.shown}") from None
        return self.shown

    def drain(self) -> None:
        while select.select([self.master], [], [], 0.05)[0]:
            try:
                chunk = os.read(self.master, 4096)
            except OSError:
                return
            if not chunk:
                return
            self.seen += chunk

    @property
    def shown(self) -> str:
        return self.seen.decode("utf-8", "replace")

    def type(self, data: bytes) -> None:
        os.write(self.master, data)

    def close(self) -> None:
        os.close(self.master)
        os.close(self.slave)


class Served:
    """`workbench serve` playing the robot on loopback, recording its run."""

    def __init__(self, tmp_path) -> None:
        maze = tmp_path / "corridor.txt"
        maze.write_text(CORRIDOR)
        self.record = tmp_path / "served.jsonl"
        self.port = free_port()
        self.process = subprocess.Popen(
            [sys.executable, "-m", "workbench", "serve", "--maze", str(maze), "--tcp-port",
             str(self.port), "--report-ms", "50", "--record", str(self.record), "--noise", "off"],
            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
        )  # fmt: skip

    def stop(self) -> list[dict]:
        """Stop serving; the tick lines of the record, written to the end."""
        if self.process.poll() is None:
            self.process.send_signal(signal.SIGINT)
            self.process.communicate(timeout=15)
        lines = self.record.read_text().splitlines()
        return [json.loads(line) for line in lines if '"t"' in line]


@pytest.fixture
def served(tmp_path):
    server = Served(tmp_path)
    try:
        yield server
    finally:
        server.stop()


def connect(program: str, terminal: Terminal, *extra: str) -> subprocess.Popen:
    return subprocess.Popen(
        [sys.executable, "-m", "workbench", "viple", "run", program, "--connect", *extra],
        stdin=terminal.slave, stdout=terminal.slave, stderr=terminal.slave,
        start_new_session=True,
    )  # fmt: skip


def test_typed_keys_drive_the_served_robot_and_ctrl_c_stops_it(tmp_path, served):
    program = drive_by_wire(tmp_path, served.port)
    terminal = Terminal()
    before = termios.tcgetattr(terminal.slave)
    client = connect(program, terminal)
    try:
        terminal.read_until("connected to")
        # raw while it drives
        wait_until(lambda: termios.tcgetattr(terminal.slave) != before, "the terminal raw")
        terminal.type(b"w")
        terminal.read_until("key w")
        terminal.read_until("print: going")
        terminal.read_until("key release")  # nothing more typed: released after the gap
        time.sleep(1.5)  # the robot stands still
        terminal.type(b"\x03")
        assert client.wait(timeout=15) == 0
        terminal.drain()
    finally:
        if client.poll() is None:
            client.kill()
            client.wait()
    shown = terminal.shown
    assert termios.tcgetattr(terminal.slave) == before  # the terminal is as it was
    terminal.close()
    assert "stopped from the keyboard" in shown
    # each line starts at the left margin even in raw mode: no line feed without a return
    assert "key w\r\n" in shown and re.search("[^\r]\n", shown) is None
    served_ticks = served.stop()
    commands = [(t["t"], c) for t in served_ticks for c in t.get("cmd", ())]
    go = next(t for t, c in commands if c.get("wheels") == [0.6, 0.6])
    halt = next(t for t, c in commands if t > go and c.get("wheels") == [0.0, 0.0])
    # w was typed once: released RELEASE_GAP later on the wall clock (the served robot runs
    # in real time), give or take the reports' 50 ms and the machine's load
    assert RELEASE_GAP - 0.15 <= halt - go <= RELEASE_GAP + 0.6
    poses = {t["t"]: t["pose"] for t in served_ticks}
    moving = [p for t, p in poses.items() if go <= t <= halt]
    assert abs(moving[-1][1] - moving[0][1]) > 0.2  # the program drove the robot...
    still = [p for t, p in poses.items() if halt + 0.3 <= t <= halt + 1.3]
    assert still and all(p == still[0] for p in still)  # ...and the release stopped it
    assert any(c.get("stop") for t, c in commands if t > halt)  # Ctrl+C sent the stop


def test_arrows_reach_the_program_and_esc_quits(tmp_path, served):
    b = ProgramBuilder()
    main = b.panel("Main")
    main.add(19, "127.0.0.1", str(served.port), "WiFi", "3000")
    up = main.add(13, "36")  # VIPLE's number for the up arrow
    main.chain(
        up, main.add(20, "0.5", "0.5", ROBOT, "3", "5"), main.add(2, '"up!"'), main.add(28, "")
    )
    program = b.write(tmp_path / "arrows.viple")
    terminal = Terminal()
    before = termios.tcgetattr(terminal.slave)
    client = connect(program, terminal)
    try:
        terminal.read_until("connected to")
        terminal.type(b"\x1b[A")
        terminal.read_until("print: up!")
        terminal.type(b"\x1b")
        assert client.wait(timeout=15) == 0
        terminal.drain()
    finally:
        if client.poll() is None:
            client.kill()
            client.wait()
    assert termios.tcgetattr(terminal.slave) == before
    terminal.close()
    assert "key up" in terminal.shown and "stopped from the keyboard" in terminal.shown
    commands = [(t["t"], c) for t in served.stop() for c in t.get("cmd", ())]
    go = next(t for t, c in commands if c.get("wheels") == [0.5, 0.5])
    assert any(c.get("stop") for t, c in commands if t > go)  # Esc stopped the robot


def test_no_keyboard_leaves_the_terminal_alone(tmp_path, served):
    program = drive_by_wire(tmp_path, served.port)
    terminal = Terminal()
    before = termios.tcgetattr(terminal.slave)
    client = connect(program, terminal, "--no-keyboard", "--duration", "1.5", "--typed", "w@0.2")
    try:
        terminal.read_until("connected to")
        assert termios.tcgetattr(terminal.slave) == before
        terminal.type(b"x")  # the terminal's own line: not read by the run
        assert client.wait(timeout=15) == 0
        terminal.drain()
    finally:
        if client.poll() is None:
            client.kill()
            client.wait()
    terminal.close()
    shown = terminal.shown
    assert "key w" in shown and "key release" in shown  # the --typed keys still drive
    assert "keys go to the program" not in shown
