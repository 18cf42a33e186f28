"""A loaded VIPLE program: panels, activities, the links rebuilt from the file, loop pairs."""

from __future__ import annotations

from dataclasses import dataclass, field

from .kinds import KindMap, kind_label

#: the output pin of an If's or Switch's Else/default branch
ELSE = -1


@dataclass(frozen=True)
class Variable:
    name: str
    type: str


@dataclass(frozen=True)
class Activity:
    """One block of a diagram. ``values`` are its arguments as VIPLE saved them (text)."""

    id: int
    kind: int
    panel: str
    name: str
    values: tuple[str, ...]

    def value(self, index: int) -> str:
        return self.values[index] if index < len(self.values) else ""


@dataclass(frozen=True)
class Link:
    """A connection: from ``source``'s output ``pin`` (``ELSE`` for Else) to ``target``'s
    input ``in_pin`` (0 unless the target is a Join)."""

    edge: int
    source: int
    pin: int
    target: int
    in_pin: int = 0


@dataclass(frozen=True)
class Panel:
    """A diagram tab: Main, or the body of the custom activity of this name."""

    name: str
    inputs: tuple[Variable, ...]
    activities: tuple[int, ...]


@dataclass
class Program:
    source: str
    version: str
    digest: str
    panels: dict[str, Panel]
    activities: dict[int, Activity]
    globals: tuple[Variable, ...]
    links: tuple[Link, ...]
    kinds: KindMap = field(default_factory=dict)
    #: source id -> output pin -> links leaving it, in the file's order
    outputs: dict[int, dict[int, tuple[Link, ...]]] = field(default_factory=dict)
    #: target id -> links entering it
    inputs: dict[int, tuple[Link, ...]] = field(default_factory=dict)
    #: While id -> its End While id, and back
    loop_end: dict[int, int] = field(default_factory=dict)
    loop_start: dict[int, int] = field(default_factory=dict)
    #: Break id -> the While it leaves
    break_loop: dict[int, int] = field(default_factory=dict)

    def targets(self, activity: int, pin: int = 0) -> tuple[Link, ...]:
        return self.outputs.get(activity, {}).get(pin, ())

    def label(self, activity: Activity) -> str:
        """What an activity is, for messages: its kind, and a block's name."""
        text = kind_label(activity.kind, self.kinds)
        return f"{text} {activity.name}" if activity.name else text

    def pin_of(self, panel: str, kind: int) -> int | None:
        """The id of the Input, Output or Event pin (kind -1/-2/-3) of a custom panel."""
        for aid in self.panels[panel].activities:
            if self.activities[aid].kind == kind:
                return aid
        return None
