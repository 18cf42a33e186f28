"""Motor commands in the form a robot with two driven wheels understands: Robot Drive's powers.

VIPLE's Robot+ services (Move at Power, Turn by Degree) reach the Unity simulator as entries
with ``servoId`` -1. A robot's own VIPLE middleware knows its two wheel ports and nothing else;
it may fail on any other message, and then not even the stop gets through. :class:`WheelDrive`
turns every command into the two wheel powers of the profile's robot, so that each message
carries one entry for the left and one for the right wheel port:

* Move at Power: both wheels at the speed the profile's Move at Power drives;
* Turn by Degree: a spin in place at the profile's turn rate (or the fastest spin the wheels
  give, when that is slower), then both wheels stop once the angle's time is up;
* Robot Motor: the one wheel changes, the other keeps its power;
* Stop: both wheels at 0.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from workbench.sim.commands import (
    Command,
    MotorPower,
    MoveAtPower,
    Stop,
    TurnByDegrees,
    WheelPowers,
)
from workbench.sim.profiles import Profile


def move_power(power: float, profile: Profile) -> float:
    """The wheel power that drives as fast as Move at Power ``power`` does in ``profile``."""
    if profile.move_sign_only:
        speed = math.copysign(profile.move_speed, power) if power else 0.0
    else:
        speed = profile.move_speed * power
    return speed / profile.max_wheel_speed


def spin_power(profile: Profile) -> float:
    """The wheel power (left +, right -) that spins at the profile's Turn by Degree rate, at
    most 1."""
    wanted = math.radians(profile.turn_rate) * profile.track_width / 2.0
    return min(1.0, wanted / profile.max_wheel_speed)


def spin_rate(profile: Profile) -> float:
    """Degrees a second of the spin at :func:`spin_power`."""
    speed = spin_power(profile) * profile.max_wheel_speed
    return math.degrees(2.0 * speed / profile.track_width)


@dataclass
class WheelDrive:
    """Turns each command into wheel powers, keeping the powers last sent and the end of a
    spin in progress (on the caller's clock, seconds)."""

    profile: Profile
    left: float = 0.0
    right: float = 0.0
    spin_ends: float | None = None

    def powers(self, t: float, cmd: Command) -> WheelPowers:
        """The wheel powers for ``cmd`` sent at ``t``; a Turn by Degree starts a spin that
        :meth:`spin_over` ends."""
        self.spin_ends = None
        if isinstance(cmd, WheelPowers):
            out = cmd
        elif isinstance(cmd, MotorPower):
            out = (
                WheelPowers(cmd.power, self.right)
                if cmd.wheel == "left"
                else WheelPowers(self.left, cmd.power)
            )
        elif isinstance(cmd, MoveAtPower):
            power = move_power(cmd.power, self.profile)
            out = WheelPowers(power, power)
        elif isinstance(cmd, TurnByDegrees):
            out = self._spin(t, float(cmd.degrees))
        elif isinstance(cmd, Stop):
            out = WheelPowers(0.0, 0.0)
        else:
            raise TypeError(f"not a motor command: {cmd!r}")
        self.left, self.right = out.left, out.right
        return out

    def _spin(self, t: float, degrees: float) -> WheelPowers:
        if not math.isfinite(degrees) or degrees == 0.0:
            return WheelPowers(0.0, 0.0)  # no (finite) angle to turn: the robot stands
        power = math.copysign(spin_power(self.profile), degrees)
        self.spin_ends = t + abs(degrees) / spin_rate(self.profile)
        return WheelPowers(power, -power)

    def spin_over(self, t: float) -> bool:
        """True once, when a spin's time is up at ``t``: the caller then sends a stop."""
        if self.spin_ends is None or t < self.spin_ends:
            return False
        self.spin_ends = None
        return True
