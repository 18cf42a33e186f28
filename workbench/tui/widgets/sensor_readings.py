"""Live sensor readings by port, as the robot reports them to VIPLE."""

from __future__ import annotations

from textual.reactive import var
from textual.widgets import Static

from workbench.sim.profiles import get_profile
from workbench.sim.session import Snapshot

from .text import reading


class SensorReadings(Static):
    """One line per sensor: port, kind, mount and the current reading."""

    DEFAULT_CSS = """
    SensorReadings {
        height: auto;
        padding: 0 1;
        border-top: solid $primary;
        border-title-color: $text-primary;
    }
    """

    lines: var[tuple[str, ...]] = var(())

    def __init__(self, *, id: str | None = None, classes: str | None = None) -> None:
        super().__init__(id=id, classes=classes, markup=False)
        self.border_title = "Sensors by port"

    def show(self, snapshot: Snapshot, profile: str) -> None:
        p = get_profile(profile)
        lines = []
        for spec in sorted(snapshot.sensors, key=lambda s: s.port):
            value = reading(spec, snapshot.readings.get(spec.port), p.unit, p.no_echo)
            lines.append(f"{spec.port:>2} {spec.kind:<8} {spec.mount:<5} {value}")
        self.lines = tuple(lines) or ("no sensors: o opens the ports",)

    def watch_lines(self, old: tuple[str, ...], lines: tuple[str, ...]) -> None:
        # new readings every tick: a layout pass only when the number of lines changes
        self.update("\n".join(lines), layout=len(old) != len(lines))
