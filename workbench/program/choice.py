"""A program file chosen to drive the lab station's robot, as the app loads it.

:func:`choose_program` reads the file through the station's file rules (a served student
reaches only their workspace), loads, checks and compiles it, and hands the station a
:class:`~workbench.control.station.ProgramChoice`: a maker of the program driving afresh, the
check of the robot's sensors, and the lines that describe the program.
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from dataclasses import replace

from workbench.control.station import LabStation, ProgramChoice
from workbench.sim.sensor_kinds import sensor_kind
from workbench.sim.sensors import SensorSpec

from . import kinds as K
from .compiled import Compiled
from .loader import is_program_name
from .pilot import SENSOR_NEEDS, check_sensors, load_compiled, program_driving
from .problems import ProgramError

_SENSOR_WORDS = {
    K.TOUCH: "touch",
    K.DISTANCE: "distance",
    K.OTHER_SENSOR: "sensor",
    K.RAW_SENSOR: "every sensor (raw report)",
}


def is_program_path(text: str) -> bool:
    """A path the app loads as a VIPLE program (``.viple``, VIPLE 3.x ``.xml``)."""
    return is_program_name(text)


def choose_program(station: LabStation, path: str) -> ProgramChoice:
    """Load the program at ``path`` (as the student typed it) and choose it on the station.

    A program with problems raises :class:`ProgramError` naming the file as the student
    typed it; a file outside the workspace raises ``OutsideWorkspace``.
    """
    choice = load_choice(station, path)
    station.use_program(choice)
    return choice


def load_choice(station: LabStation, path: str) -> ProgramChoice:
    """Load the program at ``path`` as :func:`choose_program` does, without choosing it: the
    part that may take a while (an app does it beside its event loop), changing nothing."""
    files = station.files
    real = files.for_reading(path)
    shown = files.shown(real)
    try:
        compiled = load_compiled(str(real))
    except ProgramError as exc:
        raise ProgramError([replace(p, source=shown) for p in exc.problems]) from None
    return program_choice(compiled, shown)


def program_choice(compiled: Compiled, shown: str) -> ProgramChoice:
    program = compiled.program

    def needs(sensors: Sequence[SensorSpec]) -> str | None:
        problems = check_sensors(compiled, list(sensors))
        if not problems:
            return None
        # the hints name command-line options; in the app the sensor ports panel sets them
        return "\n".join(str(replace(p, source=shown, hint="")) for p in problems)

    return ProgramChoice(
        name=os.path.basename(shown),
        source=shown,
        digest=program.digest,
        make=lambda report_ms: program_driving(compiled, shown, report_ms),
        needs=needs,
        summary=tuple(describe_choice(compiled)),
        fit=lambda sensors: fit_sensors(compiled, sensors),
    )


def fit_sensors(
    compiled: Compiled, sensors: Sequence[SensorSpec]
) -> tuple[list[SensorSpec], str | None]:
    """``sensors`` with a sensor of the kind the program reads at each port it reads (a
    sensor already there keeps its mount; a new one takes a free mount), and what cannot be
    fitted: a diagram reading more ports than a robot has mounts."""
    by_port = {s.port: s for s in sensors}
    cannot = []
    for kind, port in sorted(set(compiled.sensors.values()), key=lambda kp: kp[1]):
        if kind == K.RAW_SENSOR:
            continue  # it reads whatever the robot has
        have = by_port.get(port)
        wanted = SENSOR_NEEDS[kind]
        if have is not None and have.kind in wanted:
            continue
        used = {s.mount for p, s in by_port.items() if p != port}
        free = [m for m in sensor_kind(wanted[0]).mounts if m not in used]
        if have is not None and have.mount in free:
            mount = have.mount
        elif free:
            mount = free[0]
        else:
            cannot.append(f"port {port} ({wanted[0]}): every mount has a sensor already")
            continue
        by_port[port] = SensorSpec(wanted[0], port, mount)
    if any(kind == K.RAW_SENSOR for kind, _ in compiled.sensors.values()) and not by_port:
        cannot.append("it reads the robot's raw report: give the robot a sensor with o")
    fitted = [by_port[p] for p in sorted(by_port)]
    return fitted, "; ".join(cannot) or None


def describe_choice(compiled: Compiled) -> list[str]:
    """What the program is and what it answers, in a few short lines."""
    program = compiled.program
    acts = len(program.activities)
    panels = len(program.panels)
    lines = [
        f"VIPLE {program.version}: {acts} activit{'y' if acts == 1 else 'ies'}, "
        f"{panels} panel{'' if panels == 1 else 's'}",
        f"sha256 {program.digest[:16]}...",
    ]
    keys = sorted({"+".join(sorted(k)) for k in compiled.key_sets.values() if k})
    releases = any(a.kind == K.KEY_RELEASE for a in program.activities.values())
    if keys or releases:
        lines.append("keys it answers: " + ", ".join(keys + (["release"] if releases else [])))
    sensors = sorted(set(compiled.sensors.values()), key=lambda kp: (kp[1], kp[0]))
    if sensors:
        lines.append("sensors it reads:")
        lines += [
            f"  {_SENSOR_WORDS[kind]}" + (f" on port {port}" if port >= 0 else "")
            for kind, port in sensors
        ]
    else:
        lines.append("sensors it reads: none")
    return lines
