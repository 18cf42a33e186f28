"""Sensors as VIPLE sees them: a kind, the port number the student chose, and a mount side.

The kinds, and the mounts each allows, are the table of :mod:`workbench.sim.sensor_kinds`."""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass

from .sensor_kinds import KINDS, MOUNTS, is_kind, sensor_kind

__all__ = [
    "KINDS",
    "MOUNTS",
    "MOUNT_ANGLES",
    "PORT_RANGE",
    "SensorConfigError",
    "SensorSpec",
    "check_ports",
]

#: mount -> angle in degrees clockwise from the robot's heading
MOUNT_ANGLES = {"front": 0, "right": 90, "back": 180, "left": 270}
PORT_RANGE = range(0, 100)


class SensorConfigError(ValueError):
    """A sensor specification or configuration that cannot be used, with the reason."""


@dataclass(frozen=True)
class SensorSpec:
    kind: str
    port: int
    mount: str

    def __post_init__(self) -> None:
        if not isinstance(self.kind, str) or not is_kind(self.kind):
            raise SensorConfigError(
                f"unknown sensor kind {self.kind!r}: use one of {', '.join(KINDS)}"
            )
        if self.mount not in MOUNTS:
            raise SensorConfigError(f"unknown mount {self.mount!r}: use one of {', '.join(MOUNTS)}")
        allowed = sensor_kind(self.kind).mounts
        if self.mount not in allowed:
            raise SensorConfigError(
                f"a {self.kind} sensor cannot be mounted {self.mount}: "
                f"use one of {', '.join(allowed)}"
            )
        if (
            isinstance(self.port, bool)
            or not isinstance(self.port, int)
            or self.port not in PORT_RANGE
        ):
            raise SensorConfigError(
                f"port {self.port!r} is out of range: use a whole number from "
                f"{PORT_RANGE.start} to {PORT_RANGE.stop - 1}"
            )

    def __str__(self) -> str:
        return f"{self.kind}:{self.port}:{self.mount}"

    @classmethod
    def parse(cls, text: str) -> SensorSpec:
        """``KIND:PORT:MOUNT``, e.g. ``distance:1:right`` (the form of ``--sensor``)."""
        parts = text.split(":")
        if len(parts) != 3:
            raise SensorConfigError(
                f"sensor {text!r} must be KIND:PORT:MOUNT, e.g. distance:1:right"
            )
        kind, port, mount = (p.strip() for p in parts)
        try:
            port_no = int(port)
        except ValueError:
            raise SensorConfigError(
                f"sensor {text!r}: port {port!r} is not a whole number"
            ) from None
        return cls(kind, port_no, mount)


def check_ports(specs: Iterable[SensorSpec]) -> list[SensorSpec]:
    """Return the specs as a list, or raise naming both sensors that share a port."""
    seen: dict[int, SensorSpec] = {}
    out = []
    for spec in specs:
        if spec.port in seen:
            raise SensorConfigError(
                f"port {spec.port} is used twice: by {seen[spec.port]} and by {spec}; "
                "give each sensor its own port"
            )
        seen[spec.port] = spec
        out.append(spec)
    return out
