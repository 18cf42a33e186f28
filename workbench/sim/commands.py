"""The motor commands a controller (keys, an FSM, a VIPLE program) hands to the simulation.

They mirror VIPLE's robot services. Powers are clamped to [-1, 1] when the command is made.
"""

from __future__ import annotations

from dataclasses import dataclass


def clamp_power(value: float) -> float:
    return max(-1.0, min(1.0, float(value)))


@dataclass(frozen=True)
class WheelPowers:
    """Robot Drive: both wheel powers at once; they hold until the next command."""

    left: float
    right: float

    def __post_init__(self) -> None:
        object.__setattr__(self, "left", clamp_power(self.left))
        object.__setattr__(self, "right", clamp_power(self.right))


@dataclass(frozen=True)
class MotorPower:
    """Robot Motor: one wheel's power (``wheel`` is "left" or "right"); the other holds."""

    wheel: str
    power: float

    def __post_init__(self) -> None:
        if self.wheel not in ("left", "right"):
            raise ValueError(f"wheel must be 'left' or 'right', not {self.wheel!r}")
        object.__setattr__(self, "power", clamp_power(self.power))


@dataclass(frozen=True)
class MoveAtPower:
    """Robot+ Move at Power: the whole robot forward (> 0), backward (< 0) or stopped (0)."""

    power: float

    def __post_init__(self) -> None:
        object.__setattr__(self, "power", clamp_power(self.power))


@dataclass(frozen=True)
class TurnByDegrees:
    """Robot+ Turn by Degree: turn in place, + right (clockwise seen from above), - left."""

    degrees: float


@dataclass(frozen=True)
class Stop:
    """Both wheels to zero and any turn in progress abandoned."""


Command = WheelPowers | MotorPower | MoveAtPower | TurnByDegrees | Stop


def motion_of(cmd: object) -> str | None:
    """What a command asks the robot to do, as a drive key's name: forward, backward, left,
    right or stop (None for one wheel alone, which says nothing about the whole robot)."""
    if isinstance(cmd, Stop):
        return "stop"
    if isinstance(cmd, MoveAtPower):
        return "forward" if cmd.power > 0 else "backward" if cmd.power < 0 else "stop"
    if isinstance(cmd, TurnByDegrees):
        return "right" if cmd.degrees > 0 else "left" if cmd.degrees < 0 else None
    if isinstance(cmd, WheelPowers):
        left, right = cmd.left, cmd.right
        if left == right:
            return "forward" if left > 0 else "backward" if left < 0 else "stop"
        return "right" if left > right else "left"
    return None
