"""Replaying a run record: a cursor over its ticks, stepped by hand or played on simulated time.

:func:`load_replay` reads a JSONL run record (see ``docs/run-record.md``) and checks every tick
line, so a malformed record fails at once with its line number rather than half-way through a
replay. :class:`Replay` then gives the recorded pose, sensor readings, state and events at its
current tick. Playing runs on simulated time: ``advance(wall_seconds)`` moves
``wall_seconds * speed`` seconds of the run forward, so a replay at 1x takes as long as the run.
"""

from __future__ import annotations

import bisect
import math
import os
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any, TypeGuard

from workbench.files.workspace import LOCAL, FileAccess, OutsideWorkspace

from .maze import Maze, MazeError
from .mazeio import load_maze
from .metrics import Metrics, TurnCounter, efficiency
from .record import RecordError, RunRecord, iter_lines, read_record, recorded_driver
from .sensors import SensorConfigError, SensorSpec
from .session import Snapshot
from .wallmaze import source_file
from .world import Pose

#: the playing speeds offered, as factors of simulated time over wall time
SPEEDS: tuple[float, ...] = (0.25, 0.5, 1.0, 2.0, 4.0, 10.0, 50.0)
DEFAULT_SPEED = 1.0


@dataclass(frozen=True)
class Frame:
    """What the record says at one tick."""

    index: int
    t: float
    pose: Pose
    sensors: dict[int, float | int]
    commands: tuple[dict[str, Any], ...]
    state: str | None
    variables: dict[str, Any]
    events: tuple[str, ...]

    def block(self, cell: float) -> tuple[int, int]:
        """The maze block the robot's centre is in, for blocks of ``cell`` units."""
        return int(self.pose.x // cell), int(self.pose.y // cell)


def _number(value: Any) -> TypeGuard[float]:
    return isinstance(value, int | float) and not isinstance(value, bool) and math.isfinite(value)


def tick_problem(tick: dict[str, Any]) -> str | None:
    """Why a tick line cannot be replayed, or None when it can."""
    if not _number(tick.get("t")):
        return 'a tick line needs "t", the simulated time in seconds'
    pose = tick.get("pose")
    if not (isinstance(pose, list) and len(pose) == 3 and all(_number(v) for v in pose)):
        return '"pose" must be [x, y, heading], three numbers'
    sensors = tick.get("sensors", {})
    if not isinstance(sensors, dict):
        return '"sensors" must map port numbers to readings'
    for port, value in sensors.items():
        if not str(port).isdigit():
            return f'sensor port {port!r} in "sensors" is not a whole number'
        if not _number(value):
            return f"sensor {port} reading {value!r} is not a number"
    if not isinstance(tick.get("cmd", []), list):
        return '"cmd" must be a list of commands'
    state = tick.get("state")
    if state is not None and not isinstance(state, str):
        return '"state" must be a state name'
    if not isinstance(tick.get("vars", {}), dict):
        return '"vars" must map variable names to values'
    events = tick.get("events", [])
    if not (isinstance(events, list) and all(isinstance(e, str) for e in events)):
        return '"events" must be a list of event names'
    return None


def _tick_line(path: str | os.PathLike, index: int) -> int | None:
    """The file line of the ``index``-th tick line (found again only when reporting an error)."""
    seen = -1
    try:
        for no, obj in iter_lines(path):
            if "type" not in obj:
                seen += 1
                if seen == index:
                    return no
    except (OSError, ValueError):
        return None
    return None


def load_replay(path: str | os.PathLike) -> Replay:
    """Read and check a run record; :class:`RecordError` names the file, line and reason."""
    try:
        record = read_record(path)
    except UnicodeDecodeError:
        raise RecordError(f"{path}: not a text file, so not a run record") from None
    try:
        return Replay(record)
    except _TickError as exc:
        line = _tick_line(path, exc.index)
        where = f"{path}:{line}" if line is not None else f"{path}: tick {exc.index + 1}"
        raise RecordError(f"{where}: {exc.reason}") from None
    except RecordError as exc:
        raise RecordError(f"{path}: {exc}") from None


class _TickError(RecordError):
    def __init__(self, index: int, reason: str) -> None:
        super().__init__(f"tick {index + 1}: {reason}")
        self.index = index
        self.reason = reason


def _header_sensors(header: dict[str, Any]) -> tuple[SensorSpec, ...]:
    raw = header.get("sensors", [])
    if not isinstance(raw, list):
        raise RecordError('header: "sensors" must be a list of KIND:PORT:MOUNT')
    specs = []
    for text in raw:
        try:
            specs.append(SensorSpec.parse(str(text)))
        except SensorConfigError as exc:
            raise RecordError(f"header: sensor {text!r}: {exc}") from None
    return tuple(specs)


def _metrics_so_far(
    record: RunRecord, poses: list[Pose], times: list[float], cell: float
) -> list[Metrics]:
    info = record.header.get("maze")
    shortest = info.get("shortest_path") if isinstance(info, dict) else None
    shortest = shortest if isinstance(shortest, int) and not isinstance(shortest, bool) else None
    out: list[Metrics] = []
    distance = turning = 0.0
    collisions = touches = 0
    exit_time: float | None = None
    counter = TurnCounter()
    for i, tick in enumerate(record.ticks):
        if i:
            a, b = poses[i - 1], poses[i]
            distance += math.hypot(b.x - a.x, b.y - a.y)
            turn = (b.heading - a.heading + 180.0) % 360.0 - 180.0
            turning += abs(turn)
            counter.update(turn, times[i] - times[i - 1])
        events = tick.get("events", ())
        collisions += sum(e == "collision" for e in events)
        touches += sum(e == "touch" for e in events)
        if exit_time is None and "exit" in events:
            exit_time = times[i]
        reached = exit_time is not None
        out.append(
            Metrics(
                reached_exit=reached,
                exit_time=exit_time,
                sim_time=times[i],
                distance=distance,
                distance_cells=distance / cell,
                turn_degrees=turning,
                turns=counter.current(),
                collisions=collisions,
                touches=touches,
                efficiency=efficiency(shortest, cell, distance, reached),
            )
        )
    return out


def _changes(ticks: list[dict[str, Any]]) -> list[tuple[int, str]]:
    """(tick index, line) for every state change and event of a run, in order."""
    lines: list[tuple[int, str]] = []
    previous: str | None = None
    for i, tick in enumerate(ticks):
        state = tick.get("state")
        t = float(tick["t"])
        if state is not None and state != previous:
            text = f"{previous} -> {state}" if previous is not None else f"start in {state}"
            lines.append((i, f"{t:7.2f}s {text}"))
            previous = state
        for event in tick.get("events", ()):
            lines.append((i, f"{t:7.2f}s {event}"))
    return lines


class Replay:
    """A cursor over a run record's ticks, stepped or played at a speed factor."""

    def __init__(self, record: RunRecord) -> None:
        if not record.ticks:
            raise RecordError("the record has no tick lines: nothing to replay")
        previous = -math.inf
        for i, tick in enumerate(record.ticks):
            reason = tick_problem(tick)
            if reason is None and tick["t"] < previous:
                reason = f"time goes backwards ({tick['t']} after {previous})"
            if reason is not None:
                raise _TickError(i, reason)
            previous = tick["t"]
        self.record = record
        self.sensors = _header_sensors(record.header)
        #: who drove the run
        self.driver = recorded_driver(record.header)
        self.times = [float(t["t"]) for t in record.ticks]
        self.poses = [Pose(*(float(v) for v in t["pose"])) for t in record.ticks]
        self._log = _changes(record.ticks)
        self._log_ticks = [i for i, _ in self._log]
        self._metrics = _metrics_so_far(record, self.poses, self.times, self.cell)
        self.index = 0
        self.time = self.times[0]
        self.playing = False
        self.speed = DEFAULT_SPEED

    # -- what the record says --------------------------------------------------------------
    @property
    def header(self) -> dict[str, Any]:
        return self.record.header

    @property
    def summary(self) -> dict[str, Any] | None:
        return self.record.summary

    def __len__(self) -> int:
        return len(self.times)

    @property
    def at_start(self) -> bool:
        return self.index == 0

    @property
    def at_end(self) -> bool:
        return self.index == len(self.times) - 1

    @property
    def duration(self) -> float:
        return self.times[-1] - self.times[0]

    @property
    def cell(self) -> float:
        """The block size the run used (profile units); 1.0 when the header lacks it."""
        cell = self.header.get("cell")
        return float(cell) if _number(cell) and cell > 0 else 1.0

    @property
    def title(self) -> str:
        maze = self.header.get("maze")
        name = maze.get("name") if isinstance(maze, dict) else None
        return f"{self.driver.short} on {name or 'an unnamed maze'}"

    def frame(self, index: int | None = None) -> Frame:
        i = self.index if index is None else index
        tick = self.record.ticks[i]
        x, y, heading = tick["pose"]
        return Frame(
            index=i,
            t=float(tick["t"]),
            pose=Pose(float(x), float(y), float(heading)),
            sensors={int(p): v for p, v in tick.get("sensors", {}).items()},
            commands=tuple(tick.get("cmd", ())),
            state=tick.get("state"),
            variables=dict(tick.get("vars", {})),
            events=tuple(tick.get("events", ())),
        )

    def metrics(self, index: int | None = None) -> Metrics:
        """The run's measures up to a tick, worked out from the recorded poses and events.

        Poses are recorded at the control rate, so distance and turning are sampled; the
        summary line (when the record has one) holds the exact totals of the whole run.
        """
        return self._metrics[self.index if index is None else index]

    def snapshot(self, index: int | None = None) -> Snapshot:
        """The tick as a session snapshot, for the views that draw live sessions."""
        f = self.frame(index)
        return Snapshot(
            time=f.t,
            pose=f.pose,
            block=f.block(self.cell),
            readings=dict(f.sensors),
            sensors=self.sensors,
            driver=self.driver,
            state=f.state,
            variables=f.variables,
            metrics=self.metrics(f.index),
            events=f.events,
        )

    def trail(self) -> list[Pose]:
        """The recorded poses from the first tick up to the current one."""
        return self.poses[: self.index + 1]

    def log(self, limit: int = 10) -> list[str]:
        """The last ``limit`` state changes and events up to the current tick, oldest first."""
        if limit <= 0:
            return []
        end = bisect.bisect_right(self._log_ticks, self.index)
        return [text for _, text in self._log[max(0, end - limit) : end]]

    # -- moving ----------------------------------------------------------------------------
    def jump(self, index: int) -> int:
        """Go to tick ``index`` (clamped to the record); stops playing at the last tick."""
        self.index = min(max(index, 0), len(self.times) - 1)
        self.time = self.times[self.index]
        if self.at_end:
            self.playing = False
        return self.index

    def step(self, ticks: int = 1) -> int:
        """Forward (or, negative, back) by whole ticks; stepping by hand pauses playing."""
        self.playing = False
        return self.jump(self.index + ticks)

    def to_start(self) -> int:
        self.playing = False
        return self.jump(0)

    def to_end(self) -> int:
        return self.jump(len(self.times) - 1)

    def seek(self, t: float) -> int:
        """Go to the last tick at or before simulated time ``t``."""
        i = bisect.bisect_right(self.times, t) - 1
        self.jump(max(i, 0))
        self.time = min(max(t, self.times[0]), self.times[-1])
        return self.index

    # -- playing ---------------------------------------------------------------------------
    def play(self) -> None:
        """Play from here (from the start again when at the end)."""
        if self.at_end:
            self.jump(0)
        self.playing = True

    def pause(self) -> None:
        self.playing = False

    def toggle(self) -> bool:
        """Play or pause; returns True when now playing."""
        if self.playing:
            self.pause()
        else:
            self.play()
        return self.playing

    def faster(self) -> float:
        self.speed = next((s for s in SPEEDS if s > self.speed), SPEEDS[-1])
        return self.speed

    def slower(self) -> float:
        self.speed = next((s for s in reversed(SPEEDS) if s < self.speed), SPEEDS[0])
        return self.speed

    def advance(self, wall_seconds: float) -> bool:
        """Play ``wall_seconds`` of real time at the speed factor; True when the tick changed."""
        if not self.playing or wall_seconds <= 0:
            return False
        before = self.index
        target = self.time + wall_seconds * self.speed
        if target >= self.times[-1]:
            self.to_end()
        else:
            self.seek(target)
        return self.index != before


def replay_maze(
    replay: Replay,
    record_path: str | os.PathLike,
    known: Sequence[Maze] = (),
    files: FileAccess = LOCAL,
) -> tuple[Maze | None, str]:
    """The maze the run was on, and a note for the student (empty when all is well).

    A maze in ``known`` (e.g. the station's) with the recorded layout digest wins; otherwise the
    maze file named in the header is read (as given, then beside the record). A file whose
    layout changed since the run is still used, with a warning. Only files that ``files``
    allows are read.
    """
    info = replay.header.get("maze")
    info = info if isinstance(info, dict) else {}
    digest = info.get("digest")
    for maze in known:
        if digest and maze.digest() == digest:
            return maze, ""
    source = info.get("source")
    if not isinstance(source, str) or not source or source.startswith("<"):
        return None, "the record does not name a maze file, so the maze cannot be drawn"
    named = Path(source_file(source))  # a micromouse maze was drawn from its file, as blocks
    candidates = [named]
    if not named.is_absolute():
        candidates.append(Path(record_path).parent / named)
    for typed in candidates:
        try:
            candidate = files.for_reading(typed)
        except OutsideWorkspace:
            continue
        try:
            if not candidate.is_file():
                continue
            maze = load_maze(candidate)
        except MazeError as exc:
            first = exc.problems[0].message if exc.problems else "unreadable"
            return None, f"the run's maze {candidate} cannot be read: {first}"
        except (OSError, ValueError):
            continue
        if digest and maze.digest() != digest:
            return maze, f"the maze file {candidate} has changed since this run"
        return maze, ""
    return None, f"the run's maze file {source} is not found, so the maze cannot be drawn"
