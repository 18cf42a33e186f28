"""A VIPLE program at the wheel: loaded and checked against the robot's sensors, reading them
by port, and driving the lab station's robot or a headless run (``workbench viple run``, and
``workbench eval --program``)."""

from __future__ import annotations

import os
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

from workbench.control.driving import Driving
from workbench.control.evaluate import Entrant
from workbench.control.headless import RunResult, RunSetupError, RunSpec
from workbench.files.bounded import BoundedFileError
from workbench.sim.driver import Driver
from workbench.sim.profiles import Profile, check_report_ms
from workbench.sim.sensor_kinds import DISTANCE, KINDS, TOUCH, sensor_kind
from workbench.sim.sensors import SensorSpec

from . import kinds as K
from .bundled import bundled_program
from .compiled import Compiled, compile_program
from .interp import ProgramController
from .keys import KeyEvent, parse_key_script, typed_events
from .kinds import load_kind_map
from .loader import load_program
from .problems import Problem, ProgramError, program_problem

#: which simulated sensor kinds answer each VIPLE sensor activity (the first: the kind a
#: missing sensor is added as); VIPLE's Robot Sensor reads a sensor of any kind
SENSOR_NEEDS: dict[int, tuple[str, ...]] = {
    K.DISTANCE: (DISTANCE.name,),
    K.TOUCH: (TOUCH.name,),
    K.OTHER_SENSOR: KINDS,
}


def load_compiled(path: str, kinds: str | None = None) -> Compiled:
    """Load, check and compile a program; every problem is in the :class:`ProgramError`."""
    mapping = {}
    if kinds:
        try:
            mapping = load_kind_map(kinds)
        except BoundedFileError as exc:
            raise ProgramError([program_problem(exc.path, str(exc).split(": ", 1)[1])]) from None
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
        wanted = SENSOR_NEEDS[kind]
        if spec is None or spec.kind not in wanted:
            have = f"the robot has {spec} there" if spec else "the robot has no sensor there"
            problems.append(
                _problem(
                    program,
                    act,
                    f"it reads port {port}, but {have}",
                    f"add --sensor {wanted[0]}:{port}:MOUNT (MOUNT {_either(wanted[0])})",
                )
            )
    return problems


def _either(kind: str) -> str:
    """The mounts a sensor of ``kind`` allows, as "front, right, back or left"."""
    *most, last = sensor_kind(kind).mounts
    return f"{', '.join(most)} or {last}" if most else last


def _problem(program, act, message: str, hint: str) -> Problem:
    return program_problem(
        program.source, message, hint, act.panel, act.id, act.kind, program.label(act)
    )


def port_binding(sensors: Sequence[SensorSpec]) -> dict[str, int]:
    """A program reads sensors by port: each one under the name ``port N``."""
    return {f"port {s.port}": s.port for s in sensors}


def program_driving(
    compiled: Compiled, shown: str, report_ms: int, keys: Sequence[KeyEvent] = ()
) -> Driving:
    """The program driving, from the start, as the file ``shown`` (its path as the student
    gave it), its sensors reported every ``report_ms`` as VIPLE's simulator does; ``keys`` are
    pressed at their simulated times (a headless run's script)."""
    controller = ProgramController(compiled, tuple(keys), report_period=report_ms / 1000.0)
    name = os.path.basename(shown)
    digest = compiled.program.digest
    return Driving(
        controller=controller,
        driver=Driver.program(name, digest),
        bind=port_binding,
        header={"program": name, "program_sha256": digest},
        source=shown,
        type_key=controller.type_key,
        stopped=lambda: str(controller.stopped) if controller.stopped is not None else None,
        program_name=name,
        program_sha256=digest,
        bundled=bundled_program(compiled.program),
    )


@dataclass(frozen=True)
class ProgramPilot:
    """A program file drives a headless run, with the keys of a script pressed on the way."""

    program: str
    keys: str = ""
    #: keys as a terminal types them (one key an item, repeats while held; see TypedKeys)
    typed: str = ""
    #: names for unknown activity kinds (a YAML file)
    kinds: str | None = None
    #: milliseconds between two sensor reports (None: the profile's simulator period)
    report_ms: int | None = None

    def drive(
        self, profile: Profile, sensors: list[SensorSpec] | None
    ) -> tuple[Driving, list[SensorSpec]]:
        compiled = load_compiled(self.program, self.kinds)
        try:
            report_ms = profile.report_ms if self.report_ms is None else self.report_ms
            check_report_ms(report_ms)
            keys = parse_key_script(self.keys)
            if self.typed:
                typed = typed_events(parse_key_script(self.typed), until=float("inf"))
                keys = tuple(sorted(keys + typed, key=lambda e: e.time))
        except ValueError as exc:  # the report interval, the key script (KeyScriptError)
            raise RunSetupError(str(exc)) from None
        if sensors is None:
            sensors = list(profile.sensors)
        missing = check_sensors(compiled, sensors)
        if missing:
            raise ProgramError(missing)
        return program_driving(compiled, self.program, report_ms, keys), sensors

    def result(self, run: RunResult) -> dict[str, Any]:
        controller = run.driving.controller
        assert isinstance(controller, ProgramController)
        header = run.driving.header
        return {
            **run.measures(),
            "program": header["program"],
            "program_sha256": header["program_sha256"],
            "printed": [{"time": round(p.time, 4), "text": p.text} for p in controller.printed],
            "printed_dropped": controller.printed_dropped,
            "events": [
                {"time": round(f.time, 4), "activity": f.activity, "event": f.what}
                for f in controller.fired
            ],
            "errors": [str(e) for e in controller.errors],
            "stopped": str(controller.stopped) if controller.stopped is not None else None,
        }


def program_entrant(
    path: str,
    name: str | None = None,
    kinds: str | None = None,
    profile: str | None = None,
    sensors: tuple[str, ...] = (),
    noise: str | None = None,
    noise_params: tuple[str, ...] = (),
    max_time: float | None = None,
    keys: str = "",
    report_ms: int | None = None,
) -> Entrant:
    """A program in ``workbench eval`` (named ``name``, default its path), on each maze and
    seed, with the key script ``keys`` pressed in every run and its sensors reported every
    ``report_ms`` (None: the profile's period)."""

    def spec(maze: str, seed: int) -> RunSpec:
        return RunSpec(
            maze=maze,
            pilot=ProgramPilot(path, keys=keys, kinds=kinds, report_ms=report_ms),
            profile=profile,
            sensors=sensors,
            seed=seed,
            noise=noise,
            noise_params=noise_params,
            max_time=max_time,
        )

    return Entrant(name or path, spec)
