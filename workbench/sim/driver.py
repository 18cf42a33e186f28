"""Who drives the robot: the drive keys, an algorithm, a VIPLE program, some other program, or
nobody. A :class:`Driver` is made once, where the driving starts, and read everywhere else by
its fields; its text (``str``) is what the screens and the lab evidence show.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Literal, get_args

DriverKind = Literal["keys", "algorithm", "viple", "program", "nobody"]
KINDS: tuple[str, ...] = get_args(DriverKind)


@dataclass(frozen=True)
class Driver:
    """Who drives, with the details of that kind of driver.

    ``name`` is the algorithm's name (``algorithm``) or what a program calls itself
    (``program``: a script or front end driving the session through its own API); ``role``
    (``tcp`` / ``ws``) and ``peer`` (where it connected from) belong to a VIPLE program.
    ``digest`` (sha256 of the file's bytes) marks a ``program`` that is a VIPLE program file
    the workbench runs itself.
    """

    kind: DriverKind
    name: str = ""
    role: str = ""
    peer: str = ""
    digest: str = ""

    def __post_init__(self) -> None:
        if self.kind not in KINDS:
            raise ValueError(f"unknown driver kind {self.kind!r}: use one of {', '.join(KINDS)}")

    @classmethod
    def algorithm(cls, name: str) -> Driver:
        return cls("algorithm", name=name)

    @classmethod
    def viple(cls, role: str = "", peer: str = "") -> Driver:
        return cls("viple", role=role, peer=peer)

    @classmethod
    def program(cls, name: str, digest: str = "") -> Driver:
        return cls("program", name=name, digest=digest)

    @property
    def is_viple(self) -> bool:
        return self.kind == "viple"

    @property
    def short(self) -> str:
        """The name a table of runs shows: the algorithm's own name, else the full text."""
        return self.name if self.kind == "algorithm" else str(self)

    def __str__(self) -> str:
        if self.kind == "algorithm":
            return f"algorithm {self.name}"
        if self.kind == "viple":
            return " ".join(part for part in ("VIPLE", self.role, self.peer) if part)
        if self.kind == "program":
            if self.digest:
                return f"VIPLE program {self.name}"
            return self.name or "program"
        return self.kind

    def as_json(self) -> dict[str, str]:
        """The driver as a run record's header holds it (only the fields that are set)."""
        out: dict[str, str] = {"kind": self.kind}
        for key in ("name", "role", "peer", "digest"):
            value = getattr(self, key)
            if value:
                out[key] = value
        return out

    @classmethod
    def from_json(cls, obj: Any) -> Driver | None:
        """A driver read back from :meth:`as_json`; None when ``obj`` is not one."""
        if not isinstance(obj, dict) or obj.get("kind") not in KINDS:
            return None
        fields = {key: obj.get(key, "") for key in ("name", "role", "peer", "digest")}
        if not all(isinstance(value, str) for value in fields.values()):
            return None
        return cls(obj["kind"], **fields)


BY_KEYS = Driver("keys")
NOBODY = Driver("nobody")
