"""A run's caption and graded figures, in the words the app's run panel uses.

The figures are the summary line's when the record has one (the exact totals of the run), else
those worked out from the recorded ticks (a run cut off without a summary).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

from workbench.files.terminal import terminal_safe

from .runs import PictureRun
from .series import label


@dataclass(frozen=True)
class Figures:
    """The graded figures of one run."""

    time: float
    reached_exit: bool
    exit_time: float | None
    efficiency: float | None
    distance: float
    blocks: float
    turn_degrees: float
    turns: int
    collisions: int
    touches: int
    #: the record has its summary line (False: the run was cut off, figures from the ticks)
    complete: bool


def _num(data: dict[str, Any], key: str, default: float) -> float:
    value = data.get(key)
    if isinstance(value, int | float) and not isinstance(value, bool) and math.isfinite(value):
        return float(value)
    return default


def figures(run: PictureRun) -> Figures:
    replay = run.replay
    m = replay.metrics(len(replay) - 1)
    s = replay.summary
    if s is None:
        return Figures(
            m.sim_time,
            m.reached_exit,
            m.exit_time,
            m.efficiency,
            m.distance,
            m.distance_cells,
            m.turn_degrees,
            m.turns,
            m.collisions,
            m.touches,
            False,
        )
    reached = s.get("reached_exit") is True
    exit_time = _num(s, "exit_time", math.nan) if reached else None
    eff = _num(s, "efficiency", math.nan)
    return Figures(
        time=_num(s, "sim_time", m.sim_time),
        reached_exit=reached,
        exit_time=None if exit_time is None or math.isnan(exit_time) else exit_time,
        efficiency=None if math.isnan(eff) else eff,
        distance=_num(s, "distance", m.distance),
        blocks=_num(s, "distance_cells", m.distance_cells),
        turn_degrees=_num(s, "turn_degrees", m.turn_degrees),
        turns=int(_num(s, "turns", m.turns)),
        collisions=int(_num(s, "collisions", m.collisions)),
        touches=int(_num(s, "touches", m.touches)),
        complete=True,
    )


def length(value: float, unit: str) -> str:
    """A length as the app writes it: whole pixels, two decimals for metre-like units."""
    return f"{value:.0f}" if unit == "px" else f"{value:.2f}"


def _plural(n: int, one: str, many: str = "") -> str:
    return f"{n} {one}" if n == 1 else f"{n} {many or one + 's'}"


def figure_lines(run: PictureRun) -> list[str]:
    """The run's figures: time and exit, distance, turning and turns, collisions (touches)."""
    f = figures(run)
    unit = run.profile.unit
    clock = f"t {f.time:.1f} s"
    if f.reached_exit and f.exit_time is not None:
        clock += f" | out at {f.exit_time:.1f} s"
        if f.efficiency is not None:
            clock += f" ({f.efficiency:.0%} efficient)"
    elif f.complete:
        clock += " | did not get out"
    if not f.complete:
        clock += " | the record was cut off (no summary line)"
    travel = f"distance {length(f.distance, unit)} {unit} ({f.blocks:.1f} blocks)"
    turning = f"turned {f.turn_degrees:.0f}°; {_plural(f.turns, 'turn')}"
    hits = f"collisions {f.collisions}" + (f" | touches {f.touches}" if f.touches else "")
    return [clock, f"{travel} | {turning} | {hits}"]


#: why a record stopped before its run ended, by the figure its summary's ``record_capped``
#: holds (:meth:`workbench.sim.record.Recorder.summary`)
_STOPPED_BY = {"bytes": "its size limit", "bytes_per_second": "its limit of bytes a second"}


def _capped(run: PictureRun) -> dict[str, Any] | None:
    summary = run.replay.summary
    capped = summary.get("record_capped") if summary is not None else None
    return capped if isinstance(capped, dict) else None


def _stopped_at(capped: dict[str, Any]) -> str:
    t = _num(capped, "t", math.nan)
    return "" if math.isnan(t) else f" at {t:.1f} s"


def record_stop(run: PictureRun) -> str | None:
    """When the record stopped before its run ended, the line that says so: the path drawn
    and the marks on it end there, while the figures above are the whole run's (None: the
    record holds the whole run)."""
    capped = _capped(run)
    if capped is None:
        return None
    why = next((words for key, words in _STOPPED_BY.items() if key in capped), "a limit")
    return f"the record stopped{_stopped_at(capped)} ({why}): the path and its marks end there"


def record_stop_short(run: PictureRun) -> str | None:
    """:func:`record_stop` in a few words, for a small map's title."""
    capped = _capped(run)
    return None if capped is None else f"path ends{_stopped_at(capped)} (record stopped)"


def heading(run: PictureRun) -> str:
    """Maze, profile and driver: ``eRobotic lab maze (erobotic) | driver: right-wall``."""
    maze = label(run.maze.name or "unnamed maze")
    return f"{maze} ({run.profile.name}) | driver: {label(run.replay.driver)}"


def caption(run: PictureRun) -> str:
    """The caption under a run's picture: heading, figures, and the record's name."""
    lines = [heading(run), *figure_lines(run)]
    stop = record_stop(run)
    if stop is not None:
        lines.append(stop)
    lines.append(run.record_words or f"record {label(run.name)}")
    if run.note:
        lines.append(terminal_safe(run.note))
    return "\n".join(lines)
