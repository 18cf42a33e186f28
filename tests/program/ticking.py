"""A program controller run on the test's own clock: started at 0 and ticked every
:data:`TICK` seconds, the commands it gave in order (no real time passes)."""

from __future__ import annotations

from collections.abc import Callable, Mapping

from workbench.program.interp import ProgramController

#: seconds between ticks, as the station ticks a controller
TICK = 0.05

Readings = Mapping[int, float] | Callable[[float], Mapping[int, float]]


def run(c: ProgramController, seconds: float, readings: Readings | None = None) -> list:
    """Start ``c`` and tick it for ``seconds``; every command it gave. ``readings`` are the
    sensors' values by port, the same each tick or, a function of the time, changing."""
    commands = list(c.start(0.0))
    for i in range(1, round(seconds / TICK) + 1):
        r = readings(i * TICK) if callable(readings) else (readings or {})
        commands += c.tick(i * TICK, {f"port {p}": v for p, v in r.items()}, frozenset())
    return commands


def seen(c: ProgramController, commands: list) -> tuple:
    """Everything a user sees of a run of ``c`` that gave ``commands``."""
    return (
        commands,
        [(p.time, p.text) for p in c.printed],
        c.fired,
        [str(e) for e in c.errors],
        str(c.stopped),
        c.variables,
        c.steps,
        c.changes,
        c.state,
        c.running(),
        c.next_due(),
    )
