"""Running an algorithm or a VIPLE program on a maze without a screen: the engine behind
``workbench run``, ``eval`` and ``viple run``.

A :class:`RunSpec` names the maze, the simulation's settings and its :class:`Pilot`: what
drives, as a value a worker process can take. An algorithm's pilot is here; a program's comes
from :mod:`workbench.program.pilot` (the layer above), and both runs go the one way below.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any, Protocol

from workbench.files.bundled import maze_path
from workbench.fsm.algorithms import load_algorithm
from workbench.fsm.machine import FsmRuntimeError, bind_sensors, preset_sensors
from workbench.fsm.yaml_file import parse_param_overrides
from workbench.sim.maze import Maze, MazeError
from workbench.sim.mazeio import load_maze
from workbench.sim.noise import noise_settings
from workbench.sim.profiles import Profile, get_profile
from workbench.sim.record import RecordStop
from workbench.sim.sensors import SensorSpec, check_ports
from workbench.sim.session import Session

from .driving import Driving, algorithm_driving, record_fields
from .lifecycle import Run, ending, record_file

#: keys of `workbench run --json`, in this order
RESULT_KEYS = (
    "reached_exit",
    "sim_time",
    "distance",
    "distance_cells",
    "turn_degrees",
    "turns",
    "collisions",
    "touches",
    "efficiency",
    "final_state",
    "seed",
    "cut_by_limit",
    "maze",
    "maze_digest",
    "profile",
    "driver",
)


class RunSetupError(ValueError):
    """The run cannot start: a bad maze, algorithm, sensor, parameter or noise setting."""


class RunFailed(ValueError):
    """The run ended in an error: an algorithm's guard or action failed (its record, if any,
    reads as a run cut off)."""


class Pilot(Protocol):
    """What drives a headless run, as a picklable value (a run may go to a worker process)."""

    def drive(
        self, profile: Profile, sensors: list[SensorSpec] | None
    ) -> tuple[Driving, list[SensorSpec]]:
        """Load what drives and make it ready for the robot's ``sensors`` (None: the ones it
        would have); return it with the sensors the robot carries. Bad input raises
        :class:`RunSetupError` (a program's problems raise its own error, one per line)."""
        ...

    def result(self, run: RunResult) -> dict[str, Any]:
        """The finished run as ``--json`` gives it."""
        ...


@dataclass(frozen=True)
class RunSpec:
    maze: str
    pilot: Pilot
    profile: str | None = None
    #: the robot's sensors as KIND:PORT:MOUNT (none: the ones the pilot would have)
    sensors: tuple[str, ...] = ()
    seed: int = 0
    noise: str | None = None
    noise_params: tuple[str, ...] = ()
    max_time: float | None = None
    record: str | None = None
    dt: float = 1 / 60

    def check(self) -> None:
        """Raise :class:`RunSetupError` (or the pilot's error) when this run cannot start."""
        prepare(self)

    def execute(self) -> dict[str, Any]:
        """Run it; the result as ``--json`` gives it."""
        return run(self).as_dict()


@dataclass
class RunResult:
    spec: RunSpec
    maze: Maze
    profile: str
    driving: Driving
    metrics: dict[str, Any]
    cut_by_limit: bool
    max_time: float
    #: why the run record stopped before the run ended (None: complete, or no record)
    record_stop: RecordStop | None = None

    @property
    def final_state(self) -> str:
        return self.driving.controller.state or ""

    def measures(self) -> dict[str, Any]:
        """Every measure and how the run ended, before the pilot picks and adds its own."""
        return {
            **self.metrics,
            "final_state": self.final_state,
            "seed": self.spec.seed,
            "cut_by_limit": self.cut_by_limit,
            # what ran: the maze (its name and layout digest), the profile and who drove
            "maze": self.maze.name,
            "maze_digest": self.maze.digest(),
            "profile": self.profile,
            "driver": str(self.driving.driver),
        }

    def as_dict(self) -> dict[str, Any]:
        return self.spec.pilot.result(self)


@dataclass(frozen=True)
class AlgorithmPilot:
    """An algorithm drives: a built-in name or an FSM file, with ``NAME=VALUE`` parameters."""

    algorithm: str
    params: tuple[str, ...] = ()

    def drive(
        self, profile: Profile, sensors: list[SensorSpec] | None
    ) -> tuple[Driving, list[SensorSpec]]:
        try:
            definition = load_algorithm(self.algorithm)
            if sensors is None:
                sensors = preset_sensors(definition, profile.name)
            bind_sensors(definition, sensors, profile.name)  # a missing sensor before the params
            overrides = parse_param_overrides(definition, self.params)
            driving = algorithm_driving(definition, overrides, profile.name)
        except ValueError as exc:  # the file, a sensor it lacks, a parameter (FsmFileError...)
            raise RunSetupError(str(exc)) from None
        return driving, sensors

    def result(self, run: RunResult) -> dict[str, Any]:
        values = run.measures()
        return {key: values[key] for key in RESULT_KEYS}


def default_max_time(maze: Maze, profile: Profile, cell: float) -> float:
    """About twice the time to visit every floor block once, turning 90 degrees at each."""
    floor = sum(row.count(".") for row in maze.rows)
    speed = profile.move_speed if profile.move_sign_only else 0.5 * profile.max_wheel_speed
    wait = 5.0 if profile.name == "unity" else 1.0  # the Unity programs wait after each turn
    per_block = cell / speed + 90.0 / profile.turn_rate + wait
    return float(round(max(60.0, 2.0 * floor * per_block)))


def parse_noise_params(items: Sequence[str]) -> dict[str, float]:
    out: dict[str, float] = {}
    for item in items:
        name, sep, value = item.partition("=")
        if not sep:
            raise RunSetupError(f"noise setting {item!r} must be NAME=VALUE, e.g. turn_error=0.02")
        try:
            out[name.strip()] = float(value)
        except ValueError:
            raise RunSetupError(f"noise setting {item!r}: {value!r} is not a number") from None
    return out


@dataclass(frozen=True)
class Prepared:
    """A run ready to go: its session with the driving attached, its time limit and the
    file its record goes to (None: unrecorded)."""

    session: Session
    driving: Driving
    max_time: float
    record: str | None = None


def prepare(spec: RunSpec) -> Prepared:
    """Load and check everything the run needs; bad input is a :class:`RunSetupError` (or the
    pilot's own error)."""
    try:
        maze = load_maze(maze_path(spec.maze))
    except MazeError as exc:
        raise RunSetupError(str(exc)) from None
    problems = maze.validate()
    if problems:
        raise RunSetupError("\n".join(str(p) for p in problems))
    try:
        profile = get_profile(spec.profile or maze.profile or "unity")
        given = check_ports(SensorSpec.parse(s) for s in spec.sensors) if spec.sensors else None
    except ValueError as exc:  # an unknown profile, a bad sensor (SensorConfigError)
        raise RunSetupError(str(exc)) from None
    driving, sensors = spec.pilot.drive(profile, given)
    try:
        noise = noise_settings(
            spec.noise or profile.noise, profile, **parse_noise_params(spec.noise_params)
        )
        session = Session(maze, profile.name, sensors, noise, spec.seed, spec.dt)
    except ValueError as exc:  # a bad noise setting, sensor or world (WorldError...)
        raise RunSetupError(str(exc)) from None
    session.attach(driving.controller, driving.bind(sensors), driving.driver)
    max_time = spec.max_time or default_max_time(maze, profile, session.world.cell)
    return Prepared(session, driving, max_time, spec.record)


def run(spec: RunSpec) -> RunResult:
    ready = prepare(spec)
    session, driving = ready.session, ready.driving
    try:
        recorder = record_file(ready.record) if ready.record else None
    except OSError as exc:
        raise RunSetupError(f"{exc.filename}: cannot write the record: {exc.strerror}") from None
    the_run = Run.start(
        session, recorder, **record_fields(driving.driver, driving), max_time=ready.max_time
    )
    try:
        try:
            metrics = session.run(
                ready.max_time,
                # a program stopped past its limits never moves again: the run ends there
                # (the session's steps end at the exit and at the limit themselves)
                given_up=(
                    (lambda: ending(session, driving) is not None)
                    if driving.stopped is not None
                    else None
                ),
            )
        except FsmRuntimeError as exc:  # as at the station, the run ends in an error
            raise RunFailed(f"the run failed after {session.world.time:.2f} s: {exc}") from None
        cut = bool(session.maze.exits) and not metrics.reached_exit
        the_run.end(final_state=driving.controller.state, cut_by_limit=cut)
    finally:
        the_run.close()
    return RunResult(
        spec=spec,
        maze=session.maze,
        profile=session.profile.name,
        driving=driving,
        metrics=metrics.as_dict(),
        cut_by_limit=cut,
        max_time=ready.max_time,
        record_stop=the_run.record_stop,
    )
