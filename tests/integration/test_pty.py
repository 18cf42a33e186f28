"""The real ``workbench`` executable in a pseudo-terminal, read back through a terminal
emulator: a broken entry point, terminal set-up or first screen cannot hide behind the
headless test driver."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import time
from pathlib import Path

import pexpect
import pyte
import pytest

from .ssh_support import line_with

ROOT = Path(__file__).resolve().parents[2]
COLUMNS, LINES = 80, 24


def workbench_command() -> list[str]:
    script = Path(sys.executable).parent / "workbench"
    if script.exists():
        return [str(script)]
    found = shutil.which("workbench")
    if found is None:
        pytest.fail("the workbench console script is not installed (pip install -e .)")
    return [found]


def clean_env(data_home: Path) -> dict[str, str]:
    env = {k: v for k, v in os.environ.items() if not k.startswith(("TEXTUAL", "SSH_"))}
    env.update(TERM="xterm-256color", COLUMNS=str(COLUMNS), LINES=str(LINES), LANG="C.UTF-8")
    # run records go to the test's own folder, not the home of whoever runs the tests
    env["XDG_DATA_HOME"] = str(data_home)
    return env


class Terminal:
    """A child process on a pty, its output fed into an emulated 80x24 screen."""

    def __init__(self, args: list[str], data_home: Path) -> None:
        self.screen = pyte.Screen(COLUMNS, LINES)
        self.stream = pyte.ByteStream(self.screen)
        command, *rest = args
        self.child = pexpect.spawn(
            command, rest, cwd=str(ROOT), env=clean_env(data_home), dimensions=(LINES, COLUMNS)
        )

    def text(self) -> str:
        return "\n".join(self.screen.display)

    def pump(self, seconds: float) -> None:
        end = time.monotonic() + seconds
        while time.monotonic() < end:
            try:
                data = self.child.read_nonblocking(65536, timeout=0.05)
            except pexpect.TIMEOUT:
                continue
            except pexpect.EOF:
                return
            self.stream.feed(data)

    def wait_for(self, *needles: str, timeout: float = 20.0) -> str:
        """The screen once every needle is on it (the app draws in several updates)."""
        end = time.monotonic() + timeout
        while time.monotonic() < end:
            self.pump(0.1)
            text = self.text()
            if all(needle in text for needle in needles):
                return text
            if not self.child.isalive():
                break
        missing = [n for n in needles if n not in self.text()]
        raise AssertionError(f"{missing} not on the screen after {timeout} s:\n{self.text()}")

    def send(self, keys: str) -> None:
        self.child.send(keys)

    def wait_exit(self, timeout: float = 15.0) -> int:
        end = time.monotonic() + timeout
        while self.child.isalive() and time.monotonic() < end:
            self.pump(0.1)
        if self.child.isalive():
            self.child.terminate(force=True)
            raise AssertionError(f"still running {timeout} s after ctrl+q:\n{self.text()}")
        self.child.close()
        return self.child.exitstatus


def test_workbench_opens_the_app_drives_and_quits_with_ctrl_q(tmp_path):
    term = Terminal(workbench_command(), tmp_path)
    try:
        # first the names: the student's is the login name, filled in; the partner is typed
        term.wait_for("Who is at this robot?", "Student", "Partner")
        term.send("\t")
        term.send("Bea Partner\r")
        screen = term.wait_for(
            "Keys (unity)",
            "w   forward (Move at Power 1)",
            "Run: Unity default (unity)",
            "driver: keys",
            "distance 0.00 unit",
            "^q Quit",
        )
        assert "##" in screen.splitlines()[0]  # the maze, in ASCII
        assert "& Bea Partner (student)" in screen
        term.send("w")  # Move at Power 1: the robot drives down the corridor in real time
        screen = term.wait_for("running at 1x")
        end = time.monotonic() + 10
        while "distance 0.00 unit" in screen and time.monotonic() < end:
            screen = term.wait_for("unit (")
        moved = line_with(screen, "unit (")
        assert moved.strip().startswith("distance ") and "distance 0.00" not in moved, screen
        term.send(" ")
        term.send("?")
        term.wait_for("Help: keys of the workbench")
        term.send("\x1b")
        term.wait_for("Keys (unity)")
        term.send("\x11")  # ctrl+q
        assert term.wait_exit() == 0
    finally:
        if term.child.isalive():
            term.child.terminate(force=True)


def test_a_bad_profile_is_refused_before_the_app_starts(tmp_path):
    result = subprocess.run(
        [*workbench_command(), "--profile", "lego"],
        cwd=ROOT,
        env=clean_env(tmp_path),
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert result.returncode == 2
    assert result.stderr.startswith("workbench: unknown profile 'lego'")
    assert "Traceback" not in result.stderr and result.stdout == ""
