"""Every kind of sensor a robot may carry, in one table (:data:`SENSOR_KINDS`).

An entry says all the workbench needs to know of a kind: its name (as ``--sensor``, FSM
files, lab files and run records write it), how it reads the world, the mounts it allows,
what the sensor port panel, the map and a replay show of a reading, and what a VIPLE sensor
report sends for it. The world, the station's port panel, the TUI, the VIPLE codec and the
checks of FSM files, lab files and VIPLE programs all read this table and test no kind's
name, so a new kind is one entry here and its tests (``docs/architecture.md``).

The values are plain data: the TUI turns a :class:`PanelForm` into text, the codec turns a
:class:`ReportForm` into JSON.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from functools import partial
from typing import Literal, Protocol

#: the sides a sensor may be mounted on, in the order the world numbers them
MOUNTS = ("front", "right", "back", "left")


#: the readings of one step by port
Readings = dict[int, float | int]


class Probe(Protocol):
    """What a sensor may ask of the world at one step; a mount is an index of MOUNTS."""

    def echoes(self, sensors: Sequence[tuple[int, int]], out: Readings) -> None:
        """Into ``out`` by port, for sensors ``(port, mount)`` in that order: how far a ray
        from each meets a wall, with the distance noise of the run (the profile's no-echo value
        when it meets none within range)."""
        ...

    def pressed(self, mount: int) -> bool:
        """Whether a wall touches the robot within the mount's arc."""
        ...


#: how a kind reads the world: given a probe and a set-up's sensors of this kind as
#: ``(port, mount)`` pairs (a mount is an index of MOUNTS), in order, the function that reads
#: them all at the probe's current step into the readings it is given, in that order; made
#: once per sensor set-up, so reading them all is one call
Read = Callable[[Probe, tuple[tuple[int, int], ...]], Callable[[Readings], None]]

#: a reading's unit: the profile's length unit ("length"), or none (a count or a state)
Unit = Literal["length", "none"]
#: what the map draws for a sensor: the ray to the wall it sees, a mark where it touches, nothing
Mark = Literal["ray", "contact", "none"]


@dataclass(frozen=True)
class PanelForm:
    """What the sensor port panel, the map's tooltip and a replay show of a kind's readings."""

    #: the kind's word in the panel's kind list and beside each reading
    label: str
    unit: Unit
    #: the words of a two-state reading, for 0 and for anything else (empty: a number)
    states: tuple[str, str] | None = None
    #: a reading at or past the profile's no-echo value reads as "no echo"
    echo: bool = False
    mark: Mark = "none"

    def state(self, value: float | int) -> str | None:
        """The word for a two-state reading (None: the reading is shown as a number)."""
        if self.states is None:
            return None
        return self.states[1] if value else self.states[0]


@dataclass(frozen=True)
class ReportForm:
    """What a VIPLE sensor report carries for a kind: its ``name`` and how its value is written."""

    name: str
    #: sent as the whole number 0 or 1 (VIPLE's touch sensor); else a number with ``places``
    #: decimals at most
    binary: bool = False
    places: int = 3


@dataclass(frozen=True)
class SensorKind:
    name: str
    read: Read
    mounts: tuple[str, ...]
    panel: PanelForm
    report: ReportForm
    #: rows of this kind the sensor port panel always offers, mounted or not
    offered: int = 0
    #: a wall met gently within its arc is a touch, not a collision (``docs/run-record.md``)
    bumper: bool = False


def _echo(probe: Probe, sensors: tuple[tuple[int, int], ...]) -> Callable[[Readings], None]:
    return partial(probe.echoes, sensors)


def _pressed(probe: Probe, sensors: tuple[tuple[int, int], ...]) -> Callable[[Readings], None]:
    pressed = probe.pressed

    def read(out: Readings) -> None:
        for port, mount in sensors:
            out[port] = int(pressed(mount))

    return read


DISTANCE = SensorKind(
    "distance",
    read=_echo,
    mounts=MOUNTS,
    panel=PanelForm("distance", "length", echo=True, mark="ray"),
    report=ReportForm("distance"),
    offered=2,
)
TOUCH = SensorKind(
    "touch",
    read=_pressed,
    mounts=MOUNTS,
    panel=PanelForm("touch", "none", states=("free", "pressed"), mark="contact"),
    report=ReportForm("touch", binary=True),
    offered=1,
    bumper=True,
)

#: every kind, in the order the world reads them and the panel lists them
SENSOR_KINDS: tuple[SensorKind, ...] = (DISTANCE, TOUCH)
KINDS: tuple[str, ...] = tuple(k.name for k in SENSOR_KINDS)
_BY_NAME = {k.name: k for k in SENSOR_KINDS}
#: the kinds of the rows the sensor port panel always offers, in the panel's order
PANEL_KINDS: tuple[str, ...] = tuple(k.name for k in SENSOR_KINDS for _ in range(k.offered))


def sensor_kind(name: str) -> SensorKind:
    """The entry of a kind by its name (a ``KeyError`` for a name not in the table: a
    :class:`~workbench.sim.sensors.SensorSpec` holds only known ones)."""
    return _BY_NAME[name]


def is_kind(name: str) -> bool:
    return name in _BY_NAME
