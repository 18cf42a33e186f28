"""A robot's own VIPLE middleware on loopback, for the tests: a real TCP server that sends the
reports a script gives it and keeps every command line it receives.

Like a robot's listener, it may accept only some messages: the first it does not accept
"breaks" it (``broken`` says which), and no later command counts, the final stop included.
"""

from __future__ import annotations

import json
import socket
import threading
import time
from collections.abc import Callable
from typing import Any

#: how long the robot waits for commands after each report before it sends the next one
LISTEN_S = 0.05
#: a run that goes on longer than this is cut off (the test then fails on what it lacks)
GIVE_UP_S = 60.0


def wheel_powers(message: Any, left: int = 3, right: int = 5) -> tuple[float, float] | None:
    """(left, right) when ``message`` is Robot Drive's two wheel entries, else None."""
    if not isinstance(message, dict) or set(message) != {"servos"}:
        return None
    entries = message["servos"]
    if not isinstance(entries, list) or len(entries) != 2:
        return None
    by_port = {e.get("servoId"): e.get("servoSpeed") for e in entries if isinstance(e, dict)}
    if set(by_port) != {left, right}:
        return None
    powers = by_port[left], by_port[right]
    if not all(isinstance(p, int | float) and not isinstance(p, bool) for p in powers):
        return None
    return float(powers[0]), float(powers[1])


class FakeRobot:
    """Serves one connection. ``script(robot)`` is asked for each next report (bytes), or
    None to close the connection; the robot also stops when the client closes."""

    def __init__(
        self,
        script: Callable[[FakeRobot], bytes | None],
        accepts: Callable[[Any], bool] = lambda message: True,
    ) -> None:
        self.script = script
        self.accepts = accepts
        #: every command line received, as JSON, in order (up to the one that broke it)
        self.commands: list[Any] = []
        self.broken: str | None = None
        self.reports_sent = 0
        self._pending = b""
        self._server = socket.create_server(("127.0.0.1", 0))
        self.port = self._server.getsockname()[1]
        self._thread = threading.Thread(target=self._serve, daemon=True)

    @property
    def url(self) -> str:
        return f"tcp://127.0.0.1:{self.port}"

    def __enter__(self) -> FakeRobot:
        self._thread.start()
        return self

    def __exit__(self, *exc: object) -> None:
        self._server.close()
        self._thread.join(timeout=10)

    def powers(self) -> list[tuple[float, float] | None]:
        return [wheel_powers(message) for message in self.commands]

    def _serve(self) -> None:
        self._server.settimeout(GIVE_UP_S)
        try:
            conn, _ = self._server.accept()
        except OSError:
            return
        with conn:
            deadline = time.monotonic() + GIVE_UP_S
            while time.monotonic() < deadline:
                report = self.script(self)
                if report is None:
                    return
                try:
                    conn.sendall(report)
                except OSError:
                    return
                self.reports_sent += 1
                if not self._listen(conn, time.monotonic() + LISTEN_S):
                    return

    def _listen(self, conn: socket.socket, until: float) -> bool:
        """Read commands until ``until``; False when the client has gone."""
        while (left := until - time.monotonic()) > 0:
            conn.settimeout(left)
            try:
                data = conn.recv(65536)
            except TimeoutError:
                return True
            except OSError:
                return False
            if not data:
                return False
            self._pending += data
            *lines, self._pending = self._pending.split(b"\n")
            for line in lines:
                self._command(line)
        return True

    def _command(self, line: bytes) -> None:
        if self.broken is not None or not line.strip():
            return
        try:
            message = json.loads(line)
        except ValueError:
            message = None
        if message is None or not self.accepts(message):
            self.broken = line.decode("utf-8", "replace").strip()
            return
        self.commands.append(message)


def collapsed(items: list[Any]) -> list[Any]:
    """``items`` with each run of equal neighbours kept once."""
    out: list[Any] = []
    for item in items:
        if not out or out[-1] != item:
            out.append(item)
    return out
