"""Seeded error models: unequal motors, inexact turns, noisy distance readings.

Every random draw goes through the one ``random.Random`` the world owns, so the same seed
gives the same run and a different seed (with noise on) a different one.

Levels (standard deviations; ``c`` is the profile's block size):

==========  =================  ===================  ==================  ====================
level       motor imbalance    turn error           distance, relative  distance, absolute
==========  =================  ===================  ==================  ====================
off         0                  0                    0                   0
low         0.001 % per wheel  0.05 % of each turn  0.2 % of reading    0.001 c
realistic   0.5 % per wheel    2 % of each turn     2 % of reading      0.005 c
==========  =================  ===================  ==================  ====================

Driving straight, the motor imbalance turns the robot slowly (``bench/fidelity.py``, 200
seeds, web at power 0.5): "low" about 0.05 degrees per minute (90 % of seeds under 0.1),
"realistic" about 25 degrees per minute (90 % under 51), enough that a program without
corrections ends up at a wall, which is what the course's self-adjusting exercise is about.
"low" stays near exact because a plain wall follower never measures its heading: whatever
the motors and turns get wrong adds up over a whole run, and a 16 x 16 maze takes some 40
simulated minutes (docs/profiles.md, "Noise levels").
"""

from __future__ import annotations

import math
import random
from dataclasses import dataclass, fields, replace
from typing import Any

from .profiles import NOISE_LEVELS, Profile

#: level -> (motor_imbalance, turn_error, distance_relative, distance_absolute / cell)
_LEVELS: dict[str, tuple[float, float, float, float]] = {
    "off": (0.0, 0.0, 0.0, 0.0),
    "low": (0.00001, 0.0005, 0.002, 0.001),
    "realistic": (0.005, 0.02, 0.02, 0.005),
}
_MAX_FRACTION = 0.5


@dataclass(frozen=True)
class NoiseSettings:
    """Standard deviations of the error models; all zero means a perfect robot."""

    level: str = "off"
    #: each wheel's gain is 1 + N(0, motor_imbalance), drawn once per run
    motor_imbalance: float = 0.0
    #: each Turn by Degree turns d * (1 + N(0, turn_error))
    turn_error: float = 0.0
    #: a distance reading d gets N(0, distance_relative * d + distance_absolute) added
    distance_relative: float = 0.0
    #: in profile units
    distance_absolute: float = 0.0

    def __post_init__(self) -> None:
        for f in fields(self):
            if f.name == "level":
                continue
            value = getattr(self, f.name)
            if (
                isinstance(value, bool)
                or not isinstance(value, int | float)
                or not math.isfinite(value)
                or value < 0
            ):
                raise ValueError(f"noise {f.name} must be a number >= 0, not {value!r}")
        for name in ("motor_imbalance", "turn_error", "distance_relative"):
            if getattr(self, name) > _MAX_FRACTION:
                raise ValueError(
                    f"noise {name} is a fraction (0.01 = 1 %); "
                    f"{getattr(self, name)!r} is more than {_MAX_FRACTION}"
                )

    @property
    def enabled(self) -> bool:
        return any(
            (self.motor_imbalance, self.turn_error, self.distance_relative, self.distance_absolute)
        )

    def as_dict(self) -> dict[str, object]:
        return {f.name: getattr(self, f.name) for f in fields(self)}


def noise_settings(level: str, profile: Profile, **overrides: float) -> NoiseSettings:
    """The settings of a named level for a profile, with any field overridden by keyword."""
    try:
        imbalance, turn, relative, absolute = _LEVELS[level]
    except (KeyError, TypeError):
        raise ValueError(
            f"unknown noise level {level!r}: use one of {', '.join(NOISE_LEVELS)}"
        ) from None
    settings = NoiseSettings(
        level=level,
        motor_imbalance=imbalance,
        turn_error=turn,
        distance_relative=relative,
        distance_absolute=absolute * profile.cell,
    )
    names = {f.name for f in fields(NoiseSettings)} - {"level"}
    unknown = sorted(set(overrides) - names)
    if unknown:
        raise ValueError(
            f"unknown noise setting {', '.join(unknown)}: use {', '.join(sorted(names))}"
        )
    # the names were checked above, so no override can reach the str-typed "level"
    changes: dict[str, Any] = dict(overrides)
    return replace(settings, **changes) if changes else settings


def motor_gains(settings: NoiseSettings, rng: random.Random) -> tuple[float, float]:
    """The (left, right) wheel gains of one run."""
    sigma = settings.motor_imbalance
    if not sigma:
        return 1.0, 1.0
    left = max(0.0, 1.0 + rng.gauss(0.0, sigma))
    right = max(0.0, 1.0 + rng.gauss(0.0, sigma))
    return left, right


def turn_factor(settings: NoiseSettings, rng: random.Random) -> float:
    """How much of a commanded Turn by Degree the robot really turns (1.0 = exact)."""
    sigma = settings.turn_error
    return max(0.0, 1.0 + rng.gauss(0.0, sigma)) if sigma else 1.0
