"""Running an algorithm on a maze without a screen: the engine behind `workbench run` and `eval`."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

from workbench.sim.driver import Driver
from workbench.sim.maze import Maze, MazeError
from workbench.sim.mazeio import load_maze
from workbench.sim.noise import noise_settings
from workbench.sim.profiles import Profile, get_profile
from workbench.sim.record import Recorder
from workbench.sim.sensors import SensorConfigError, SensorSpec, check_ports
from workbench.sim.session import Session
from workbench.sim.world import WorldError

from .algorithms import load_algorithm
from .fsm import FsmController, FsmError, bind_sensors, preset_sensors
from .fsmfile import FsmFileError, parse_param_overrides

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
)


class RunSetupError(ValueError):
    """The run cannot start: a bad maze, algorithm, sensor, parameter or noise setting."""


@dataclass(frozen=True)
class RunSpec:
    maze: str
    algorithm: str
    profile: str | None = None
    sensors: tuple[str, ...] = ()
    seed: int = 0
    noise: str | None = None
    noise_params: tuple[str, ...] = ()
    params: tuple[str, ...] = ()
    max_time: float | None = None
    record: str | None = None
    dt: float = 1 / 60

    def check(self) -> None:
        """Raise :class:`RunSetupError` when this run cannot start (nothing runs)."""
        prepare(self)

    def execute(self) -> dict[str, Any]:
        """Run it; the result as ``workbench run --json`` gives it."""
        return run(self).as_dict()


@dataclass
class RunResult:
    spec: RunSpec
    maze: Maze
    profile: str
    metrics: dict[str, Any]
    final_state: str
    cut_by_limit: bool
    max_time: float
    params: dict[str, float] = field(default_factory=dict)

    def as_dict(self) -> dict[str, Any]:
        values = {
            **self.metrics,
            "final_state": self.final_state,
            "seed": self.spec.seed,
            "cut_by_limit": self.cut_by_limit,
        }
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


def prepare(spec: RunSpec) -> tuple[Session, FsmController, dict[str, float], float]:
    """Load and check everything the run needs; bad input is a :class:`RunSetupError`."""
    try:
        maze = load_maze(spec.maze)
    except MazeError as exc:
        raise RunSetupError(str(exc)) from None
    problems = maze.validate()
    if problems:
        raise RunSetupError("\n".join(str(p) for p in problems))
    try:
        profile = get_profile(spec.profile or maze.profile or "unity")
        definition = load_algorithm(spec.algorithm)
        if spec.sensors:
            sensors = check_ports(SensorSpec.parse(s) for s in spec.sensors)
        else:
            sensors = preset_sensors(definition, profile.name)
        binding = bind_sensors(definition, sensors, profile.name)
        overrides = parse_param_overrides(definition, spec.params)
        controller = FsmController(definition, overrides, profile.name)
        noise = noise_settings(
            spec.noise or profile.noise, profile, **parse_noise_params(spec.noise_params)
        )
        recorder = Recorder(spec.record) if spec.record else None
        session = Session(maze, profile.name, sensors, noise, spec.seed, spec.dt, recorder=recorder)
    except (FsmFileError, FsmError, SensorConfigError, WorldError, ValueError) as exc:
        raise RunSetupError(str(exc)) from None
    except OSError as exc:
        raise RunSetupError(f"{exc.filename}: cannot write the record: {exc.strerror}") from None
    session.attach(controller, binding, Driver.algorithm(definition.name))
    max_time = spec.max_time or default_max_time(maze, profile, session.world.cell)
    return session, controller, controller.params, max_time


def run(spec: RunSpec) -> RunResult:
    session, controller, params, max_time = prepare(spec)
    session.record_header(
        algorithm=controller.definition.name,
        driven_by=session.driver.as_json(),
        params=params,
        max_time=max_time,
    )
    try:
        metrics = session.run(max_time)
        cut = bool(session.maze.exits) and not metrics.reached_exit
        session.record_summary(final_state=controller.state, cut_by_limit=cut)
    finally:
        if session.recorder is not None:
            session.recorder.close()
    return RunResult(
        spec=spec,
        maze=session.maze,
        profile=session.profile.name,
        metrics=metrics.as_dict(),
        final_state=controller.state,
        cut_by_limit=cut,
        max_time=max_time,
        params=params,
    )
