"""Two state machines compared by what they make the robot do, not by how they are written.

:func:`compare` runs a reference machine and a student's machine headless (the one runner of
:mod:`workbench.control.headless`) on the same mazes, profile, sensors and seeds, and watches
the motor commands each hands the robot. They behave the same when they give the same
commands at the same simulated times; the names of their states, the order they are written
in, how many states they use and their variables are theirs to choose. A drive command given
again while it is already in force (a second ``move: 1`` with no turn between) changes nothing
on the robot and counts once.

The student's run stops at the first difference, and the :class:`Difference` says where: the
maze and seed, the time, what the sensors read then, what the reference did and what the
student's machine did. Both runs are bounded: by the simulated time limit of the run and by a
wall-clock deadline shared by all runs of one comparison (:class:`OutOfTime`), so a machine
that is slow to evaluate cannot hold a thread for ever.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any

from workbench.fsm.machine import FsmDefinition, FsmError, bind_sensors, preset_sensors
from workbench.sim.commands import MotorPower, MoveAtPower, Stop, TurnByDegrees, WheelPowers
from workbench.sim.profiles import Profile
from workbench.sim.sensors import SensorSpec

from .driving import Driving, algorithm_driving
from .headless import RunResult, RunSetupError, RunSpec, prepare

#: two command times closer than this are the same control tick, seconds
_SAME_TICK = 1e-6
#: the longest a whole comparison may take on the wall clock, seconds
DEFAULT_DEADLINE = 20.0


class OutOfTime(Exception):
    """The comparison ran past its wall-clock deadline."""


def describe(command: Any) -> str:
    """A motor command in the words of the FSM format: ``move 1``, ``turn -90``..."""
    if isinstance(command, MoveAtPower):
        return f"move {command.power:g}"
    if isinstance(command, TurnByDegrees):
        return f"turn {command.degrees:g}"
    if isinstance(command, WheelPowers):
        return f"wheels [{command.left:g}, {command.right:g}]"
    if isinstance(command, MotorPower):
        return f"motor {command.wheel} {command.power:g}"
    if isinstance(command, Stop):
        return "stop"
    return repr(command)


@dataclass(frozen=True)
class Act:
    """One command a machine gave: when, what, and what its sensors read then (by mount)."""

    time: float
    command: str
    readings: tuple[tuple[str, float], ...] = ()


@dataclass(frozen=True)
class Difference:
    """Where two machines first did something different."""

    maze: str
    seed: int
    time: float
    readings: tuple[tuple[str, float], ...]
    #: what the reference did then ("" for nothing new)
    reference: str
    #: what the student's machine did then ("" for nothing new)
    student: str
    #: what went wrong instead of a command (a guard that failed, a missing sensor), or ""
    error: str = ""

    def words(self, unit: str = "") -> str:
        """The difference in one sentence."""
        where = f"on {self.maze!r}" + (f" (seed {self.seed})" if self.seed else "")
        if self.error:
            return f"{where} at {self.time:.2f} s your machine {self.error}"
        sensors = ", ".join(f"{mount} {value:.4g}{(' ' + unit) if unit else ''}"
                            for mount, value in self.readings)  # fmt: skip
        read = f" (sensors read {sensors})" if sensors else ""
        theirs = self.reference or "nothing new"
        yours = self.student or "nothing new"
        return f"{where} at {self.time:.2f} s{read} the reference did {theirs}; yours did {yours}"


@dataclass(frozen=True)
class Verdict:
    """The comparison's outcome: the same behaviour on every run, or the first difference."""

    same: bool
    runs: int
    #: commands compared on all runs
    commands: int
    difference: Difference | None = None
    #: why it could not be judged at all (the reference failed, out of time), else ""
    problem: str = ""
    mazes: tuple[str, ...] = field(default=())


@dataclass(frozen=True)
class DefinitionPilot:
    """A headless pilot that drives with a definition already loaded (the runner's
    :class:`~workbench.control.headless.AlgorithmPilot` reads a file by name)."""

    definition: FsmDefinition

    def drive(
        self, profile: Profile, sensors: list[SensorSpec] | None
    ) -> tuple[Driving, list[SensorSpec]]:
        definition = self.definition
        try:
            if sensors is None:
                sensors = preset_sensors(definition, profile.name)
            bind_sensors(definition, sensors, profile.name)
            driving = algorithm_driving(definition, {}, profile.name)
        except ValueError as exc:
            raise RunSetupError(str(exc)) from None
        return driving, sensors

    def result(self, run: RunResult) -> dict[str, Any]:
        return run.measures()


class _Diverged(Exception):
    def __init__(self, difference: Difference) -> None:
        super().__init__(difference.reference)
        self.difference = difference


class _Watch:
    """A controller that hands on another's commands and notes each one that changes
    something, checking the wall-clock deadline every tick and, given the reference's acts,
    stopping at the first that differs."""

    def __init__(
        self,
        inner: Any,
        mounts: dict[str, str],
        deadline: float,
        where: tuple[str, int],
        expected: Sequence[Act] | None = None,
        clock: Callable[[], float] = time.monotonic,
    ) -> None:
        self.inner = inner
        self.clock = clock
        self.mounts = mounts
        self.deadline = deadline
        self.where = where
        self.expected = expected
        self.acts: list[Act] = []
        self._last = ""
        self._next = 0

    @property
    def state(self) -> str | None:
        return self.inner.state

    @property
    def variables(self) -> dict[str, Any]:
        return self.inner.variables

    def start(self, t: float) -> list[Any]:
        return self._note(t, {}, self.inner.start(t))

    def tick(self, t: float, readings: dict[str, float], events: frozenset[str]) -> list[Any]:
        if self.clock() > self.deadline:
            raise OutOfTime
        return self._note(t, readings, self.inner.tick(t, readings, events))

    def _note(self, t: float, readings: dict[str, float], commands: list[Any]) -> list[Any]:
        by_mount = tuple(sorted((self.mounts.get(k, k), float(v)) for k, v in readings.items()))
        self._missed(t)
        for command in commands:
            text = describe(command)
            if text == self._last and not isinstance(command, TurnByDegrees):
                continue  # already in force: the robot does not change
            self._last = text
            act = Act(t, text, by_mount)
            self._check(act)
            self.acts.append(act)
        return commands

    def _missed(self, t: float) -> None:
        """The reference acted before ``t`` and this machine did not."""
        expected = self.expected
        if expected is None or self._next >= len(expected):
            return
        due = expected[self._next]
        if due.time < t - _SAME_TICK:
            raise _Diverged(Difference(*self.where, due.time, due.readings, due.command, ""))

    def _check(self, act: Act) -> None:
        expected = self.expected
        if expected is None:
            return
        maze, seed = self.where
        if self._next >= len(expected):
            raise _Diverged(Difference(maze, seed, act.time, act.readings, "", act.command))
        due = expected[self._next]
        if abs(due.time - act.time) > _SAME_TICK:
            raise _Diverged(Difference(maze, seed, act.time, act.readings, "", act.command))
        if due.command != act.command:
            raise _Diverged(
                Difference(maze, seed, act.time, act.readings, due.command, act.command)
            )
        self._next += 1

    def finish(self, end: float) -> None:
        """The run is over: the reference's acts still to come were not matched."""
        expected = self.expected
        if expected is not None and self._next < len(expected):
            due = expected[self._next]
            raise _Diverged(Difference(*self.where, due.time, due.readings, due.command, ""))


def _mounts(definition: FsmDefinition) -> dict[str, str]:
    return {s.name: s.mount for s in definition.sensors}


@dataclass(frozen=True)
class Trial:
    """One run both machines make: the maze file, its name as shown, and the seed."""

    maze: str
    shown: str
    seed: int = 0


def _run(
    definition: FsmDefinition,
    trial: Trial,
    profile: str,
    sensors: tuple[str, ...],
    max_time: float | None,
    deadline: float,
    expected: Sequence[Act] | None,
    clock: Callable[[], float] = time.monotonic,
) -> list[Act]:
    spec = RunSpec(
        maze=trial.maze,
        pilot=DefinitionPilot(definition),
        profile=profile,
        sensors=sensors,
        seed=trial.seed,
        max_time=max_time,
    )
    ready = prepare(spec)
    session = ready.session
    where = (trial.shown, trial.seed)
    watch = _Watch(ready.driving.controller, _mounts(definition), deadline, where, expected, clock)
    session.attach(watch, dict(session.binding), session.driver)
    try:
        session.run(ready.max_time)
    except FsmError as exc:
        if expected is None:
            raise
        error = f"stopped: {exc}"
        raise _Diverged(Difference(*watch.where, session.world.time, (), "", "", error)) from None
    watch.finish(session.world.time)
    return watch.acts


def compare(
    reference: FsmDefinition,
    student: FsmDefinition,
    trials: Sequence[Trial],
    profile: str,
    sensors: Sequence[str] = (),
    max_time: float | None = None,
    deadline: float = DEFAULT_DEADLINE,
    clock: Callable[[], float] = time.monotonic,
) -> Verdict:
    """Run both machines on every trial and compare what they do (see the module's text).

    ``sensors`` are the robot's (``KIND:PORT:MOUNT``; none: the reference's own), ``max_time``
    the simulated limit of each run (None: the runner's default for the maze), ``deadline``
    the wall-clock seconds the whole comparison may take (by ``clock``, read every tick)."""
    until = clock() + deadline
    shown = tuple(t.shown for t in trials)
    compared = 0
    for trial in trials:
        try:
            expected = _run(reference, trial, profile, tuple(sensors), max_time, until, None, clock)
        except OutOfTime:
            return Verdict(False, 0, compared, problem=_slow(deadline), mazes=shown)
        except (RunSetupError, FsmError) as exc:
            return Verdict(False, 0, compared, problem=f"the reference cannot run: {exc}",
                           mazes=shown)  # fmt: skip
        try:
            _run(student, trial, profile, tuple(sensors), max_time, until, expected, clock)
        except _Diverged as exc:
            return Verdict(False, len(trials), compared, exc.difference, mazes=shown)
        except OutOfTime:
            return Verdict(False, 0, compared, problem=_slow(deadline), mazes=shown)
        except RunSetupError as exc:
            first = str(exc).splitlines()[0] if str(exc) else "cannot start"
            error = Difference(trial.shown, trial.seed, 0.0, (), "", "", f"cannot start: {first}")
            return Verdict(False, len(trials), compared, error, mazes=shown)
        compared += len(expected)
    return Verdict(True, len(trials), compared, mazes=shown)


def _slow(deadline: float) -> str:
    return (
        f"the comparison took longer than {deadline:g} s and was stopped: a machine with "
        "simpler guards (or fewer states that only pass on) runs faster"
    )
