"""The three course environments as simulation profiles: units, block size, robot, speeds.

Each course environment measures distance in its own unit, and the thresholds printed in the
lab text only make sense in that unit. A profile fixes the geometry so that those thresholds
work unchanged in a corridor one block wide of the profile's default block size (``cell``).
The derivations (``c`` = cell, ``r`` = robot radius, every sensor sits on the robot's edge so
a side sensor of a centred robot reads ``c/2 - r``):

========  =====================================================================================
unity     unit "unit" (metre-like). ``c = 2``, ``r = 0.18`` (robot 0.36 wide, as in the Unity
          simulator). The side sensors look out from the ends of a sensor bar 0.9 wide (0.45
          from the centre); the front sensor sits 0.1 ahead of the centre, set back behind the
          bumper. Centred side reading 1 - 0.45 = 0.55 < 1.0 ("right > 1.0" is open: a margin
          of 0.45, almost a quarter of a block); an opening reads >= 3 - 0.45 = 2.55. Front
          < 0.9 stops the centre 0.9 + 0.1 = 1.0 from the wall, on the last block's centre
          (0.1 short with the two-distance program's 1.0), so after a quarter turn the side
          reads 0.55 again. Sensors all on the robot's edge cannot do this: the course's two
          numbers are 0.1 apart, so a robot that stops at "front < 0.9" and turns reads 0.9 to
          the side, 0.1 from "open" (docs/profiles.md). Move at Power: 1 unit/s, only the sign
          counts. Turn by Degree: 35 deg/s (the simulator turned at 30-40 deg/s). Robot Drive:
          1 unit/s per wheel at power 1, spinning 90 deg/s at (1, -1). Ray range 100, 1000 =
          no echo.
web       unit "px". ``c = 70``, ``r = 10``. Centred side reading 35 - 10 = 25 (the programs'
          BaseDistance); an opening reads >= 105 - 10 = 95 > 75 (BaseDistance + 50), while the
          far wall of the corridor is at most 70 - 20 = 50 < 75. Front < 25 stops the centre
          35 from the wall, the last block's centre. Wheel speed 140 px/s at power 1, so
          (0.5, 0.5) = 70 px/s crosses a block in one second. The effective track width makes
          (0.2, -0.2) spin 60 deg/s, 90 deg in 1.5 s: track = 2 * 0.2 * 140 * 1.5 / (pi/2)
          = 53.48 px (300 deg/s at (1, -1)). Turn by Degree 60 deg/s. Range 1000 px = no echo.
erobotic  unit "px". ``c = 120``, ``r = 8``. Centred side reading 60 - 8 = 52: not open
          (<= 100) and not "too close" (>= 50, one-distance-first); an opening reads
          >= 180 - 8 = 172 > 100. Front < 50 stops the centre 58 from the wall, 2 px short of
          the last block's centre. 120 px/s at power 1 (a block per second); spin 180 deg/s
          at (1, -1); Turn by Degree 90 deg/s. Perfect sensors, exact moves and turns (noise
          off). Range 1000 px = no echo.
========  =====================================================================================

Default sensors: unity distance 1 right + distance 2 front (the Unity simulator's preset);
web distance 1 right + touch 2 front (the Web Simulator wall-following program); erobotic
distance 1 front, 2 left, 3 right. Robot Drive wheel ports: left 3, right 5 in every profile
(the protocol example's servo ids). A VIPLE program run offline gets a sensor report every
``report_ms`` (250 ms in every profile, the pace of the workbench's own VIPLE server).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from .sensors import MOUNTS, SensorSpec, check_ports

NOISE_LEVELS = ("off", "low", "realistic")
#: the interval between two sensor reports to a VIPLE program: limits and default, milliseconds
REPORT_MS_MIN = 50
REPORT_MS_MAX = 1000
REPORT_MS_DEFAULT = 250


def check_report_ms(value: object) -> int:
    """The report interval in whole milliseconds, or ``ValueError`` naming the allowed range."""
    if isinstance(value, bool) or not isinstance(value, int):
        raise ValueError(f"report interval must be a whole number of milliseconds, not {value!r}")
    if not REPORT_MS_MIN <= value <= REPORT_MS_MAX:
        raise ValueError(
            f"report interval {value} ms is out of range: use {REPORT_MS_MIN} to "
            f"{REPORT_MS_MAX} ms (VIPLE's Unity simulator used about 260)"
        )
    return value


@dataclass(frozen=True)
class Profile:
    """One course environment. Lengths are in ``unit``, speeds per simulated second."""

    name: str
    unit: str
    #: default block size; a maze's own ``cell`` overrides it for mazes of this profile
    cell: float
    #: radius of the robot's collision circle
    robot_radius: float
    #: distance from the robot's centre to a sensor on each mount, in MOUNTS order
    #: (front, right, back, left); a sensor may sit inside the robot's circle (set back) or
    #: outside it (on a bar wider than the robot)
    sensor_offsets: tuple[float, float, float, float]
    #: speed of one wheel at power 1 (Robot Drive / Robot Motor)
    max_wheel_speed: float
    #: effective distance between the wheels: angular speed = (v_left - v_right) / track
    track_width: float
    #: Move at Power speed at power 1; with ``move_sign_only`` every non-zero power gives it
    move_speed: float
    move_sign_only: bool
    #: Turn by Degree rate, degrees per second
    turn_rate: float
    #: distance sensors see walls up to this far; beyond it they report ``no_echo``
    sensor_range: float
    no_echo: float
    #: default noise level (one of NOISE_LEVELS)
    noise: str
    #: default sensor set
    sensors: tuple[SensorSpec, ...]
    #: Robot Drive servo ids of the left and right wheels
    left_port: int
    right_port: int
    #: the lab text's thresholds this geometry is built for
    blocked_below: float
    open_above: float
    description: str = ""
    #: how often the simulator reports the sensors to a VIPLE program, milliseconds (the
    #: workbench's VIPLE server reports every 250 ms; offline program runs keep that pace)
    report_ms: int = REPORT_MS_DEFAULT

    def __post_init__(self) -> None:
        positive = (
            "cell",
            "robot_radius",
            "max_wheel_speed",
            "track_width",
            "move_speed",
            "turn_rate",
            "sensor_range",
        )
        for name in positive:
            value = getattr(self, name)
            if not (isinstance(value, int | float) and math.isfinite(value) and value > 0):
                raise ValueError(f"profile {self.name!r}: {name} must be a positive number")
        if 2 * self.robot_radius >= self.cell:
            raise ValueError(
                f"profile {self.name!r}: a robot {2 * self.robot_radius:g} {self.unit} wide "
                f"does not fit a {self.cell:g} {self.unit} block"
            )
        if len(self.sensor_offsets) != len(MOUNTS):
            raise ValueError(f"profile {self.name!r}: give one sensor offset per mount {MOUNTS}")
        if self.noise not in NOISE_LEVELS:
            raise ValueError(
                f"profile {self.name!r}: noise {self.noise!r} is not one of {NOISE_LEVELS}"
            )
        check_ports(self.sensors)
        try:
            check_report_ms(self.report_ms)
        except ValueError as exc:
            raise ValueError(f"profile {self.name!r}: {exc}") from None

    def sensor_offset(self, mount: str) -> float:
        return self.sensor_offsets[MOUNTS.index(mount)]

    def centred_reading(self, mount: str = "right", cell: float | None = None) -> float:
        """What a side sensor reads with the robot centred in a one-block corridor."""
        return (cell or self.cell) / 2 - self.sensor_offset(mount)


def _track_for_spin(wheel_speed: float, spin_deg_per_s: float) -> float:
    """Track width that makes wheel powers (1, -1) spin at ``spin_deg_per_s``."""
    return 2 * wheel_speed / math.radians(spin_deg_per_s)


def _edge(radius: float) -> tuple[float, float, float, float]:
    return (radius, radius, radius, radius)


UNITY = Profile(
    name="unity",
    unit="unit",
    cell=2.0,
    robot_radius=0.18,
    sensor_offsets=(0.1, 0.45, 0.18, 0.45),
    max_wheel_speed=1.0,
    track_width=_track_for_spin(1.0, 90.0),
    move_speed=1.0,
    move_sign_only=True,
    turn_rate=35.0,
    sensor_range=100.0,
    no_echo=1000.0,
    noise="low",
    sensors=(SensorSpec("distance", 1, "right"), SensorSpec("distance", 2, "front")),
    left_port=3,
    right_port=5,
    blocked_below=0.9,
    open_above=1.0,
    description="VIPLE's Unity simulator: Robot+ Move at Power / Turn by Degree, metre units",
)

WEB = Profile(
    name="web",
    unit="px",
    cell=70.0,
    robot_radius=10.0,
    sensor_offsets=_edge(10.0),
    max_wheel_speed=140.0,
    track_width=_track_for_spin(140.0, 300.0),
    move_speed=140.0,
    move_sign_only=False,
    turn_rate=60.0,
    sensor_range=1000.0,
    no_echo=1000.0,
    noise="low",
    sensors=(SensorSpec("distance", 1, "right"), SensorSpec("touch", 2, "front")),
    left_port=3,
    right_port=5,
    blocked_below=25.0,
    open_above=75.0,
    description="the VIPLE Web Simulator: Robot Drive wheel powers, pixels",
)

EROBOTIC = Profile(
    name="erobotic",
    unit="px",
    cell=120.0,
    robot_radius=8.0,
    sensor_offsets=_edge(8.0),
    max_wheel_speed=120.0,
    track_width=_track_for_spin(120.0, 180.0),
    move_speed=120.0,
    move_sign_only=False,
    turn_rate=90.0,
    sensor_range=1000.0,
    no_echo=1000.0,
    noise="off",
    sensors=(
        SensorSpec("distance", 1, "front"),
        SensorSpec("distance", 2, "left"),
        SensorSpec("distance", 3, "right"),
    ),
    left_port=3,
    right_port=5,
    blocked_below=50.0,
    open_above=100.0,
    description="eRobotic: three perfect distance sensors, exact moves and turns, pixels",
)

PROFILES: dict[str, Profile] = {p.name: p for p in (UNITY, WEB, EROBOTIC)}


def get_profile(name: str) -> Profile:
    try:
        return PROFILES[name]
    except (KeyError, TypeError):
        raise ValueError(f"unknown profile {name!r}: use one of {', '.join(PROFILES)}") from None
