"""A VIPLE program driving a robot over VIPLE's protocol, as VIPLE itself would.

The program's own Robot activity says where the robot is (``[host, port, connType]``):
``WiFi`` makes VIPLE the TCP client of host:port (a robot or the Unity simulator), ``WSS``
makes it the WebSocket server on port (the Web Simulator connects to it). Its Robot Drive
activities name the wheel ports the commands go to.

:class:`RemoteProgram` runs the program on the client's own clock: each sensor report fires
the sensor activities (one report, one firing), and between reports the program ticks at the
control rate so its keys and waiting flows go on, and at each Timer's own time. While a Timer
runs (:attr:`RemoteProgram.timing`), the client keeps the commands' departures as far apart
as the program's times say. The protocol
side (sockets, the wire) is ``workbench.viple.client``; the command line joins the two.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, replace
from typing import Any

from . import kinds as K
from .compiled import Compiled
from .interp import Fired, Printed, ProgramController
from .keys import KeyEvent
from .problems import Problem, ProgramError, program_problem
from .viple_expr import Value

#: the program ticks at least this often between reports (the in-process control rate)
CONTROL_HZ = 20.0
CONN_TYPES = {"wifi": "tcp", "wss": "ws"}


@dataclass(frozen=True)
class RobotSettings:
    """What the program's Robot activity says: ``tcp`` to connect to host:port, or ``ws`` to
    listen on port as VIPLE's WebSocket server does."""

    scheme: str
    host: str
    port: int

    @property
    def url(self) -> str:
        tail = "/" if self.scheme == "ws" else ""
        return f"{self.scheme}://{self.host}:{self.port}{tail}"


def robot_settings(compiled: Compiled) -> RobotSettings:
    """The program's Robot activity as an endpoint; a :class:`ProgramError` when it has none
    or its settings are not a connection VIPLE makes."""
    program = compiled.program
    robots = [a for a in program.activities.values() if a.kind == K.ROBOT]
    if not robots:
        raise ProgramError(
            [
                program_problem(
                    program.source,
                    "the program has no Robot activity, so it names no robot to connect to",
                    "add one in VIPLE, or give the address: --connect tcp://HOST:PORT",
                )
            ]
        )
    act = robots[0]
    host, port, conn = act.value(0).strip(), act.value(1).strip(), act.value(2).strip()
    where = program_problem(program.source, "", "", act.panel, act.id, act.kind, program.label(act))
    scheme = CONN_TYPES.get(conn.lower())
    if scheme is None:
        message = f"the connection type {conn[:20]!r} is not WiFi or WSS"
        raise ProgramError([_at(where, message, "choose Wi-Fi or WebSocket in VIPLE")])
    if not port.isdigit() or not 0 < int(port) < 65536:
        message = f"the port {port[:20]!r} is not a number from 1 to 65535"
        raise ProgramError([_at(where, message, "set the robot's port in VIPLE")])
    if scheme == "tcp" and not host:
        raise ProgramError([_at(where, "the Wi-Fi robot has no address", "set its IP in VIPLE")])
    return RobotSettings(scheme, host or "localhost", int(port))


def _at(where: Problem, message: str, hint: str) -> Problem:
    return replace(where, message=message, hint=hint)


def wheel_ports(compiled: Compiled) -> tuple[int, int] | None:
    """The left and right wheel ports of the program's first Robot Drive (None: it has none,
    or they are not numbers)."""
    for act in compiled.program.activities.values():
        if act.kind == K.DRIVE:
            left, right = act.value(3).strip(), act.value(4).strip()
            if left.isdigit() and right.isdigit():
                return int(left), int(right)
    return None


class RemoteProgram:
    """The program on the far side of the protocol: reports (port -> value) in, commands out."""

    def __init__(self, compiled: Compiled, keys: tuple[KeyEvent, ...] = ()) -> None:
        self.controller = ProgramController(compiled, keys)
        self.readings: dict[int, Value] | None = None
        self.last_tick = -math.inf
        self._printed = 0
        self._fired = 0
        self._ports = sorted({port for _, port in compiled.sensors.values() if port >= 0})

    @property
    def state(self) -> str | None:
        return self.controller.state

    @property
    def events(self) -> int:
        return len(self.controller.fired)

    def start(self, t: float) -> list[Any]:
        self.last_tick = t
        return self.controller.start(t)

    def report(self, t: float, readings: Mapping[int, Value], text: str | None = None) -> list[Any]:
        """A report arrived: the sensor activities fire with its values (any JSON scalar, as
        sent), a raw sensor with ``text``, the report as it arrived; then the flows run."""
        self.readings = dict(readings)
        self.last_tick = t
        named = {f"port {port}": value for port, value in readings.items()}
        return self.controller.tick(t, named, frozenset(), text)

    def tick(self, t: float) -> list[Any]:
        """No report since the last tick: Timers, keys and waiting flows go on."""
        self.last_tick = t
        return self.controller.tick(t, {}, frozenset())

    def next_tick(self) -> float:
        """When to tick next: at the control rate, or sooner when a Timer or a scripted key
        is due (so a Timer ends at its own time, not at the next control tick)."""
        tick = self.last_tick + 1.0 / CONTROL_HZ
        due = self.controller.next_due()
        return tick if due is None or due > tick else due

    @property
    def timing(self) -> bool:
        """A Timer of the program runs (or a scripted key is to come): see
        :attr:`ProgramController.timing`."""
        return self.controller.timing

    def type_key(self, key: str, t: float) -> None:
        self.controller.type_key(key, t)

    def missing_ports(self, readings: Mapping[int, Value]) -> list[int]:
        """The ports the program reads that a report does not carry."""
        return [port for port in self._ports if port not in readings]

    def news(self) -> tuple[list[Printed], list[Fired]]:
        """What was printed and which events fired since the last call."""
        c = self.controller
        new = c.printed_total - self._printed
        printed = list(c.recent)[-new:] if new > 0 else []
        fired = c.fired[self._fired :]
        self._printed = c.printed_total
        self._fired = len(c.fired)
        return printed, fired
