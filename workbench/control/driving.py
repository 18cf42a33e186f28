"""What drives the robot through a run: an algorithm's controller or a VIPLE program's run.

A :class:`Driving` is made where the driving is chosen (:func:`algorithm_driving` here, a
program's in :mod:`workbench.program.pilot`) and used one way by everything that runs it: the
lab station's one driving slot and the headless runner of ``workbench run``, ``eval`` and
``viple run``.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from workbench.fsm.bundled import bundled_fsm, fsm_digest
from workbench.fsm.machine import FsmController, FsmDefinition, bind_sensors
from workbench.sim.driver import Driver
from workbench.sim.sensors import SensorSpec
from workbench.sim.session import Controller


@dataclass(frozen=True, eq=False)
class Driving:
    """A controller, who it is, how it reads the sensors, and what a run record says of it.

    Two are equal only when they are the same: each start of a run makes a new one.
    """

    controller: Controller
    #: who drives, as the screens, the runs and the records name it
    driver: Driver
    #: its sensor names bound to the ports of a set of sensors; a ``ValueError`` (naming the
    #: sensor and the fix) when the set lacks one it reads
    bind: Callable[[Sequence[SensorSpec]], dict[str, int]]
    #: what a run record's header says of it beyond its driver (see :func:`record_fields`)
    header: dict[str, Any] = field(default_factory=dict)
    #: the FSM file or program file it was read from ("" for none)
    source: str = ""
    #: a program's Key Press events: a key typed while it drives, at the simulated time
    #: (None: it does not answer keys, as an algorithm)
    type_key: Callable[[str, float], None] | None = None
    #: why it stopped itself for good (a program past its limits), None while it may run
    stopped: Callable[[], str | None] | None = None
    #: the file that drives as the student sees it named, and the digest of what runs: a
    #: program file's bytes, an FSM's text with the parameters set for it (see
    #: :func:`~.bundled.fsm_digest`); "" for none
    program_name: str = ""
    program_sha256: str = ""
    #: the file that comes with the workbench that this is, behaviour for behaviour ("" when
    #: it is none): it is not the student's own program
    bundled: str = ""


def record_fields(driver: Driver, driving: Driving | None) -> dict[str, Any]:
    """The header fields of a run record on who drove: the text older readers take
    (``algorithm``), the typed driver, the parameters in force, and the driving's own."""
    fields: dict[str, Any] = {"algorithm": str(driver), "driven_by": driver.as_json(), "params": {}}
    if driving is not None:
        fields.update(driving.header)
    return fields


def algorithm_driving(
    definition: FsmDefinition, overrides: dict[str, float], profile: str
) -> Driving:
    """An algorithm driving with ``overrides`` of its parameters (checked: an ``FsmError``)."""
    controller = FsmController(definition, overrides, profile)

    def bind(sensors: Sequence[SensorSpec]) -> dict[str, int]:
        return bind_sensors(definition, sensors, profile)

    return Driving(
        controller=controller,
        driver=Driver.algorithm(definition.name),
        bind=bind,
        header={"algorithm": definition.name, "params": controller.params},
        source=definition.source,
        program_name=Path(definition.source).name if definition.source else "",
        program_sha256=fsm_digest(definition, overrides),
        bundled=bundled_fsm(definition, controller.params, profile),
    )
