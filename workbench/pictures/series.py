"""What a record says over time, as plain values the drawings plot.

The wheel powers are the ones standing after each tick's commands (``{"wheels"}``,
``{"motor"}``, ``{"move"}`` and ``{"stop"}`` set them and they hold until the next one);
``{"turn": d}`` asks for a turn by degrees, marked where it was given: the powers are not
known while it turns (NaN, a gap in the plot) and are 0 once the turn is done. States come as spans
of ticks in one state (an FSM's state, or the program's active flows).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from workbench.files.terminal import terminal_safe
from workbench.sim.replay import Replay

#: the longest state name a picture shows whole
MAX_LABEL = 32


@dataclass(frozen=True)
class StateSpan:
    """Ticks ``first``..``last`` in one state, from time ``start`` to ``end``."""

    state: str
    start: float
    end: float


@dataclass(frozen=True)
class Powers:
    """The wheel powers standing after each tick, and the turns asked for: (time, degrees)."""

    left: tuple[float, ...]
    right: tuple[float, ...]
    turns: tuple[tuple[float, float], ...]


def label(text: object) -> str:
    """A name as a picture shows it: control characters written out, long ones cut."""
    safe = terminal_safe(str(text))
    return safe if len(safe) <= MAX_LABEL else safe[: MAX_LABEL - 3] + "..."


def _power(value: Any) -> float | None:
    if isinstance(value, int | float) and not isinstance(value, bool) and math.isfinite(value):
        return max(-1.0, min(1.0, float(value)))
    return None


def _wheels(cmd: dict[str, Any], now: list[float]) -> None:
    value = cmd.get("wheels")
    if isinstance(value, list) and len(value) == 2:
        left, right = _power(value[0]), _power(value[1])
        if left is not None and right is not None:
            now[:] = [left, right]


def _motor(cmd: dict[str, Any], now: list[float]) -> None:
    value = cmd.get("motor")
    if isinstance(value, dict):
        power = _power(value.get("power"))
        side = {"left": 0, "right": 1}.get(str(value.get("wheel")))
        if power is not None and side is not None:
            now[side] = power


def _move(cmd: dict[str, Any], now: list[float]) -> None:
    power = _power(cmd.get("move"))
    if power is not None:
        now[:] = [power, power]


def _stop(cmd: dict[str, Any], now: list[float]) -> None:
    now[:] = [0.0, 0.0]


#: what each command of a tick line does to the standing wheel powers
_COMMANDS: dict[str, Callable[[dict[str, Any], list[float]], None]] = {
    "wheels": _wheels,
    "motor": _motor,
    "move": _move,
    "stop": _stop,
}


def powers(replay: Replay) -> Powers:
    now = [0.0, 0.0]
    left: list[float] = []
    right: list[float] = []
    turns: list[tuple[float, float]] = []
    for t, tick in zip(replay.times, replay.record.ticks, strict=True):
        for cmd in tick.get("cmd", ()):
            if not isinstance(cmd, dict):
                continue
            for key, apply in _COMMANDS.items():
                if key in cmd:
                    apply(cmd, now)
            degrees = cmd.get("turn")
            if isinstance(degrees, int | float) and _power(degrees) is not None:
                turns.append((t, float(degrees)))
                now[:] = [math.nan, math.nan]
        if "turn_done" in tick.get("events", ()) and math.isnan(now[0]):
            now[:] = [0.0, 0.0]
        left.append(now[0])
        right.append(now[1])
    return Powers(tuple(left), tuple(right), tuple(turns))


def state_spans(replay: Replay) -> list[StateSpan]:
    """The run's states as spans; empty when no controller drove."""
    spans: list[StateSpan] = []
    current: str | None = None
    start = 0.0
    times = replay.times
    for t, tick in zip(times, replay.record.ticks, strict=True):
        state = tick.get("state")
        name = label(state) if isinstance(state, str) else None
        if name != current:
            if current is not None:
                spans.append(StateSpan(current, start, t))
            current, start = name, t
    if current is not None:
        spans.append(StateSpan(current, start, times[-1]))
    return spans


def event_ticks(replay: Replay, event: str) -> list[int]:
    """The ticks at which ``event`` happened (``collision``, ``touch``, ``exit``...)."""
    return [i for i, tick in enumerate(replay.record.ticks) if event in tick.get("events", ())]


def turn_ticks(replay: Replay) -> list[int]:
    """The ticks at which a turn (45 degrees or more, as the run's figures count them) ended."""
    out = []
    previous = 0
    for i in range(len(replay)):
        turns = replay.metrics(i).turns
        if turns > previous:
            out.append(i)
        previous = turns
    return out


def sensor_series(replay: Replay) -> dict[int, list[float]]:
    """Each recorded sensor port's readings, tick by tick (NaN where a tick lacks it)."""
    ports = sorted({int(p) for tick in replay.record.ticks for p in tick.get("sensors", {})})
    out: dict[int, list[float]] = {p: [] for p in ports}
    for tick in replay.record.ticks:
        readings = tick.get("sensors", {})
        for port in ports:
            value = readings.get(str(port))
            out[port].append(float(value) if value is not None else math.nan)
    return out
