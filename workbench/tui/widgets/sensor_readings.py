"""Live sensor readings by port, as the robot reports them to VIPLE."""

from __future__ import annotations

from workbench.sim.profiles import get_profile
from workbench.sim.session import Snapshot

from .text import reading
from .text_lines import TextLines


class SensorReadings(TextLines):
    """One line per sensor: port, kind, mount and the current reading."""

    DEFAULT_CSS = """
    SensorReadings {
        height: auto;
        padding: 0 1;
        border-top: solid $primary;
        border-title-color: $text-primary;
    }
    """

    def __init__(self, *, id: str | None = None, classes: str | None = None) -> None:
        super().__init__(id=id, classes=classes)
        self.border_title = "Sensors by port"

    def show(self, snapshot: Snapshot, profile: str) -> None:
        p = get_profile(profile)
        lines = []
        for spec in sorted(snapshot.sensors, key=lambda s: s.port):
            value = reading(spec, snapshot.readings.get(spec.port), p.unit, p.no_echo)
            lines.append(f"{spec.port:>2} {spec.kind:<8} {spec.mount:<5} {value}")
        self.set_lines(lines or ["no sensors: o opens the ports"])
