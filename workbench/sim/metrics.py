"""The course's measures of a run: distance travelled, total turning degrees, and more."""

from __future__ import annotations

from dataclasses import asdict, dataclass

#: a rotation counts as one turn when it sweeps at least this many degrees without pausing
TURN_MIN_DEGREES = 45.0
#: below this rate (degrees per second) the robot is not rotating (slow drift is not a turn)
ROTATING_ABOVE = 10.0


@dataclass(frozen=True)
class Metrics:
    reached_exit: bool
    exit_time: float | None
    sim_time: float
    distance: float
    distance_cells: float
    turn_degrees: float
    turns: int
    collisions: int
    efficiency: float | None
    #: intended contacts, counted apart from collisions: a touch sensor's bumper meeting a
    #: wall gently (the rule is in workbench.sim.world); 0 in records written before touches
    touches: int = 0

    def as_dict(self, digits: int = 4) -> dict[str, object]:
        out: dict[str, object] = {}
        for key, value in asdict(self).items():
            out[key] = round(value, digits) if isinstance(value, float) else value
        return out


class TurnCounter:
    """Counts turns as rotation episodes: any way of turning (Turn by Degree or wheel powers)
    that sweeps at least ``TURN_MIN_DEGREES`` counts once; 1-degree corrections do not."""

    def __init__(self) -> None:
        self.turns = 0
        #: the degrees swept by the rotation under way (0.0: none), which :meth:`update` ends
        self.sweep = 0.0

    def update(self, signed_degrees: float, seconds: float) -> None:
        """``signed_degrees`` of rotation in the last ``seconds``.

        With no rotation and no sweep under way it changes nothing (a caller may skip it then).
        """
        if not signed_degrees and not self.sweep:
            return  # not rotating, and no sweep to end: nothing changes
        rotating = seconds > 0 and abs(signed_degrees) / seconds > ROTATING_ABOVE
        if rotating and (self.sweep == 0.0 or (signed_degrees > 0) == (self.sweep > 0)):
            self.sweep += signed_degrees
            return
        self.finish()
        if rotating:
            self.sweep = signed_degrees

    def finish(self) -> None:
        if abs(self.sweep) >= TURN_MIN_DEGREES:
            self.turns += 1
        self.sweep = 0.0

    def current(self) -> int:
        """Turns so far, counting a turn still in progress once it is large enough."""
        return self.turns + (abs(self.sweep) >= TURN_MIN_DEGREES)


def efficiency(
    shortest_blocks: int | None, cell: float, distance: float, reached: bool
) -> float | None:
    """Shortest possible travel to the nearest exit / distance actually travelled.

    The shortest travel runs from the start block's centre to the edge of the exit block (the
    run ends when the robot's centre enters it): ``(blocks - 0.5) * cell``.
    """
    if not reached or shortest_blocks is None or distance <= 0:
        return None
    return max(0.0, shortest_blocks - 0.5) * cell / distance
