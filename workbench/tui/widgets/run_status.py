"""Who drives, how fast the simulation runs, and the run's metrics."""

from __future__ import annotations

from workbench.control.station import LabStation
from workbench.sim.profiles import get_profile
from workbench.sim.session import Snapshot

from .text import degrees, number, separator, set_border_title, speed
from .text_lines import TextLines


class RunStatus(TextLines):
    """Who drives; pause, speed and time; distance; turning, collisions and touches."""

    DEFAULT_CSS = """
    RunStatus {
        height: auto;
        padding: 0 1;
        border-top: solid $primary;
        border-title-color: $text-primary;
    }
    """

    def __init__(self, *, id: str | None = None, classes: str | None = None) -> None:
        # wrapped: the clock line with the exit time, or a long VIPLE line, is read whole
        super().__init__(wrap=True, id=id, classes=classes)
        set_border_title(self, "Run")

    def show(
        self, snapshot: Snapshot, station: LabStation, unicode: bool, connection: str = ""
    ) -> None:
        sep = separator(unicode)
        unit = get_profile(station.profile).unit
        m = snapshot.metrics
        state = "PAUSED" if station.paused else "running"
        set_border_title(self, f"Run: {station.maze.name} ({station.profile})")
        driver = f"driver: {snapshot.driver}"
        clock = f"{state} at {speed(station.pacer.speed)}{sep}t {snapshot.time:.1f} s"
        if m.reached_exit and m.exit_time is not None:
            clock += f"{sep}out at {m.exit_time:.1f} s"
            if m.efficiency is not None:
                clock += f" ({m.efficiency:.0%} efficient)"
        travel = f"distance {number(m.distance, unit)} {unit} ({m.distance_cells:.1f} blocks)"
        turning = (
            # every degree counts; a turn is a rotation of 45 degrees or more
            f"turned {degrees(m.turn_degrees, unicode)}; {m.turns} "
            f"turn{'' if m.turns == 1 else 's'}"
        )
        hits = f"collisions {m.collisions}"
        contact: tuple[str, ...]
        if m.touches:
            # bumps a touch sensor was meant to feel: a line of their own, beside the collisions
            contact = (turning, f"{hits}{sep}touches {m.touches}")
        else:
            contact = (f"{turning}{sep}{hits}",)
        held = _held_line(station)
        self.set_lines(
            [driver, clock, *held, travel, *contact, *([connection] if connection else [])]
        )


def _held_line(station: LabStation) -> tuple[str, ...]:
    """While paused, what a live VIPLE program sends waits: the panel says so, and counts."""
    live = station.live_viple
    if live is None or not station.paused:
        return ()
    n = station.held_count
    what = f"{n} command{'' if n == 1 else 's'}" if n else "its commands"
    return (f"{live}: {what} held while paused, not applied",)
