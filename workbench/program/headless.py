"""Running a VIPLE program on a maze without a screen: the engine of ``workbench viple run``."""

from __future__ import annotations

import os
from dataclasses import dataclass, field
from typing import Any

from workbench.control.evaluate import Entrant
from workbench.control.headless import RunSetupError, default_max_time, parse_noise_params
from workbench.files.bounded import BoundedFileError
from workbench.sim.driver import Driver
from workbench.sim.maze import Maze, MazeError
from workbench.sim.mazeio import load_maze
from workbench.sim.noise import noise_settings
from workbench.sim.profiles import get_profile
from workbench.sim.record import Recorder
from workbench.sim.sensors import SensorConfigError, SensorSpec, check_ports
from workbench.sim.session import Session
from workbench.sim.world import WorldError

from . import kinds as K
from .compiled import Compiled, compile_program
from .interp import Fired, Printed, ProgramController, RunError
from .keys import KeyScriptError, parse_key_script, typed_events
from .kinds import load_kind_map
from .loader import load_program
from .problems import Problem, ProgramError

#: which simulated sensor kinds answer each VIPLE sensor activity
_NEEDS = {K.DISTANCE: ("distance",), K.TOUCH: ("touch",), K.OTHER_SENSOR: ("distance", "touch")}


@dataclass(frozen=True)
class ProgramRunSpec:
    program: str
    maze: str
    profile: str | None = None
    sensors: tuple[str, ...] = ()
    keys: str = ""
    #: keys as a terminal types them (one key an item, repeats while held; see TypedKeys)
    typed: str = ""
    kinds: str | None = None
    seed: int = 0
    noise: str | None = None
    noise_params: tuple[str, ...] = ()
    max_time: float | None = None
    record: str | None = None
    dt: float = 1 / 60

    def check(self) -> None:
        """Raise :class:`ProgramError` or :class:`RunSetupError` when this run cannot start."""
        prepare(self)

    def execute(self) -> dict[str, Any]:
        """Run it; the result as ``workbench viple run --json`` gives it."""
        return run_program(self).as_dict()


def program_entrant(
    path: str,
    name: str | None = None,
    kinds: str | None = None,
    profile: str | None = None,
    sensors: tuple[str, ...] = (),
    noise: str | None = None,
    noise_params: tuple[str, ...] = (),
    max_time: float | None = None,
) -> Entrant:
    """A program in ``workbench eval`` (named ``name``, default its path), on each maze and seed."""

    def spec(maze: str, seed: int) -> ProgramRunSpec:
        return ProgramRunSpec(
            program=path,
            maze=maze,
            profile=profile,
            sensors=sensors,
            kinds=kinds,
            seed=seed,
            noise=noise,
            noise_params=noise_params,
            max_time=max_time,
        )

    return Entrant(name or path, spec)


@dataclass
class ProgramRunResult:
    spec: ProgramRunSpec
    maze: Maze
    profile: str
    program_name: str
    digest: str
    metrics: dict[str, Any]
    cut_by_limit: bool
    max_time: float
    printed: list[Printed] = field(default_factory=list)
    printed_dropped: int = 0
    fired: list[Fired] = field(default_factory=list)
    errors: list[RunError] = field(default_factory=list)
    final_state: str = ""

    def as_dict(self) -> dict[str, Any]:
        return {
            **self.metrics,
            "final_state": self.final_state,
            "seed": self.spec.seed,
            "cut_by_limit": self.cut_by_limit,
            "program": self.program_name,
            "program_sha256": self.digest,
            "printed": [{"time": round(p.time, 4), "text": p.text} for p in self.printed],
            "printed_dropped": self.printed_dropped,
            "events": [
                {"time": round(f.time, 4), "activity": f.activity, "event": f.what}
                for f in self.fired
            ],
            "errors": [str(e) for e in self.errors],
        }


def load_compiled(path: str, kinds: str | None = None) -> Compiled:
    """Load, check and compile a program; every problem is in the :class:`ProgramError`."""
    mapping = {}
    if kinds:
        try:
            mapping = load_kind_map(kinds)
        except BoundedFileError as exc:
            raise ProgramError([Problem(exc.path, str(exc).split(": ", 1)[1])]) from None
    return compile_program(load_program(path, mapping))


def check_sensors(compiled: Compiled, sensors: list[SensorSpec]) -> list[Problem]:
    """Each sensor the program reads must be on the robot, at its port, of a fitting kind."""
    program = compiled.program
    by_port = {s.port: s for s in sensors}
    problems = []
    for aid, (kind, port) in compiled.sensors.items():
        act = program.activities[aid]
        if kind == K.RAW_SENSOR:
            if not sensors:
                problems.append(
                    _problem(
                        program,
                        act,
                        "it reads the robot's sensors, and the robot has none",
                        "add one with --sensor",
                    )
                )
            continue
        spec = by_port.get(port)
        wanted = _NEEDS[kind]
        if spec is None or spec.kind not in wanted:
            have = f"the robot has {spec} there" if spec else "the robot has no sensor there"
            problems.append(
                _problem(
                    program,
                    act,
                    f"it reads port {port}, but {have}",
                    f"add --sensor {wanted[0]}:{port}:MOUNT (MOUNT front, right, back or left)",
                )
            )
    return problems


def _problem(program, act, message: str, hint: str) -> Problem:
    return Problem(program.source, message, hint, act.panel, act.id, act.kind, program.label(act))


def prepare(spec: ProgramRunSpec) -> tuple[Session, ProgramController, float]:
    compiled = load_compiled(spec.program, spec.kinds)
    try:
        maze = load_maze(spec.maze)
    except MazeError as exc:
        raise RunSetupError(str(exc)) from None
    problems = maze.validate()
    if problems:
        raise RunSetupError("\n".join(str(p) for p in problems))
    try:
        profile = get_profile(spec.profile or maze.profile or "unity")
        if spec.sensors:
            sensors = check_ports(SensorSpec.parse(s) for s in spec.sensors)
        else:
            sensors = list(profile.sensors)
        keys = parse_key_script(spec.keys)
        if spec.typed:
            typed = typed_events(parse_key_script(spec.typed), until=float("inf"))
            keys = tuple(sorted(keys + typed, key=lambda e: e.time))
        noise = noise_settings(
            spec.noise or profile.noise, profile, **parse_noise_params(spec.noise_params)
        )
    except (SensorConfigError, KeyScriptError, WorldError, ValueError) as exc:
        raise RunSetupError(str(exc)) from None
    missing = check_sensors(compiled, sensors)
    if missing:
        raise ProgramError(missing)
    try:
        recorder = Recorder(spec.record) if spec.record else None
    except OSError as exc:
        raise RunSetupError(f"{exc.filename}: cannot write the record: {exc.strerror}") from None
    session = Session(maze, profile.name, sensors, noise, spec.seed, spec.dt, recorder=recorder)
    controller = ProgramController(compiled, keys)
    binding = {f"port {s.port}": s.port for s in sensors}
    driver = Driver.program(os.path.basename(spec.program), compiled.program.digest)
    session.attach(controller, binding, driver)
    max_time = spec.max_time or default_max_time(maze, profile, session.world.cell)
    return session, controller, max_time


def run_program(spec: ProgramRunSpec) -> ProgramRunResult:
    """Run the program; setup problems are :class:`ProgramError` or :class:`RunSetupError`."""
    session, controller, max_time = prepare(spec)
    program = controller.program
    session.record_header(
        program=os.path.basename(spec.program), program_sha256=program.digest, max_time=max_time
    )
    try:
        metrics = session.run(max_time)
        cut = bool(session.maze.exits) and not metrics.reached_exit
        session.record_summary(final_state=controller.state, cut_by_limit=cut)
    finally:
        if session.recorder is not None:
            session.recorder.close()
    return ProgramRunResult(
        spec=spec,
        maze=session.maze,
        profile=session.profile.name,
        program_name=os.path.basename(spec.program),
        digest=program.digest,
        metrics=metrics.as_dict(),
        cut_by_limit=cut,
        max_time=max_time,
        printed=controller.printed,
        printed_dropped=controller.printed_dropped,
        fired=controller.fired,
        errors=controller.errors,
        final_state=controller.state or "",
    )
