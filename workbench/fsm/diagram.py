"""A state machine drawn as text: states as boxes, transitions as labelled arrows.

The layout is layered: the initial state first, then the states it reaches in one transition,
then those they reach, and so on (the states nothing reaches come last, marked so). Within a
layer the states keep the order they are written in. Each box is followed by its transitions,
in the order they are checked, each an arrow labelled with its guard (``always`` for none)
and the state it goes to (a guard too long for the line gets a line of its own); an arrow
back to an earlier layer (a loop) is marked ``^``, one to itself ``@``. The drawing fits in
``width`` columns; only a guard or name longer than a whole line is cut (``...``), and a front
end scrolls the lines.

:func:`layout` knows nothing of a screen: it returns the lines and, for each state and each
transition, the lines it takes, so a front end can highlight the current state and the
transition that fired last.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Any

from .definition import (
    FsmDefinition,
    MotorAction,
    MoveAction,
    SetAction,
    StopAction,
    TimerAction,
    TurnAction,
    WheelsAction,
)

#: the characters a drawing uses: (box corners and edges, arrow parts)
_UNICODE = {"tl": "┌", "tr": "┐", "bl": "└", "br": "┘", "h": "─", "v": "│",
            "branch": "├", "last": "└", "arrow": "─▶", "dots": "…"}  # fmt: skip
_ASCII = {"tl": "+", "tr": "+", "bl": "+", "br": "+", "h": "-", "v": "|",
          "branch": "+", "last": "`", "arrow": "->", "dots": "..."}  # fmt: skip
#: the narrowest drawing: a box name and an arrow need this much
MIN_WIDTH = 20
#: the most states drawn (a file may hold thousands; nobody reads a diagram of them)
MAX_STATES = 200


@dataclass(frozen=True)
class Diagram:
    """A drawn machine: its lines, and where each part of it is."""

    lines: tuple[str, ...]
    #: state name -> (first line, last line) of its box
    boxes: Mapping[str, tuple[int, int]] = field(default_factory=dict)
    #: (state, index of the transition in it) -> (first line, last line) of its arrow
    arrows: Mapping[tuple[str, int], tuple[int, int]] = field(default_factory=dict)
    #: the states in the order drawn, with their layer (0: the initial state)
    layers: tuple[tuple[str, int], ...] = ()

    @property
    def width(self) -> int:
        return max((len(line) for line in self.lines), default=0)

    def text(self) -> str:
        return "\n".join(self.lines)


def layers_of(definition: FsmDefinition) -> list[tuple[str, int]]:
    """Each state with its layer: how many transitions from the initial state it is, in a
    breadth-first walk; states nothing reaches get the layer after the last (-1 if none)."""
    names = [s.name for s in definition.states]
    targets = {s.name: [t.target for t in s.transitions] for s in definition.states}
    depth: dict[str, int] = {}
    if definition.initial in targets:
        depth[definition.initial] = 0
        frontier = [definition.initial]
        while frontier:
            nxt: list[str] = []
            for name in frontier:
                for target in targets.get(name, ()):
                    if target in targets and target not in depth:
                        depth[target] = depth[name] + 1
                        nxt.append(target)
            frontier = nxt
    unreached = max(depth.values(), default=-1) + 1
    placed = [(n, depth.get(n, -1)) for n in names]
    order = {n: i for i, n in enumerate(names)}
    return sorted(placed, key=lambda p: (p[1] if p[1] >= 0 else unreached, order[p[0]]))


def _cut(text: str, room: int, dots: str) -> str:
    if len(text) <= room:
        return text
    if room <= len(dots):
        return dots[:room]
    return text[: room - len(dots)] + dots


def layout(
    definition: FsmDefinition,
    width: int = 80,
    unicode: bool = True,
    notes: Mapping[str, str] | None = None,
) -> Diagram:
    """Draw ``definition`` in at most ``width`` columns (``notes``: a short text per state
    shown in its box under the name, e.g. its actions)."""
    ch = _UNICODE if unicode else _ASCII
    width = max(MIN_WIDTH, width)
    placed = layers_of(definition)
    layer = dict(placed)
    left_out = len(placed) - MAX_STATES
    placed = placed[:MAX_STATES]
    states = {s.name: s for s in definition.states}
    lines: list[str] = []
    boxes: dict[str, tuple[int, int]] = {}
    arrows: dict[tuple[str, int], tuple[int, int]] = {}
    shown_layer = None
    for name, depth in placed:
        heading = f"step {depth}" if depth >= 0 else "not reached from the start"
        if depth != shown_layer:
            if lines:
                lines.append("")
            lines.append(_cut(f"{heading}:", width, ch["dots"]))
            shown_layer = depth
        state = states[name]
        title = name + ("  (start)" if name == definition.initial else "")
        body = [title]
        note = (notes or {}).get(name, "")
        if note:
            body.append(note)
        inner = min(max(len(b) for b in body), width - 4)
        first = len(lines)
        lines.append(ch["tl"] + ch["h"] * (inner + 2) + ch["tr"])
        for part in body:
            lines.append(f"{ch['v']} {_cut(part, inner, ch['dots']).ljust(inner)} {ch['v']}")
        lines.append(ch["bl"] + ch["h"] * (inner + 2) + ch["br"])
        boxes[name] = (first, len(lines) - 1)
        count = len(state.transitions)
        if not count:
            lines.append(_cut("  (final: no transitions)", width, ch["dots"]))
        for j, tr in enumerate(state.transitions):
            lead = f" {ch['last'] if j == count - 1 else ch['branch']}{ch['h']} "
            target_depth = layer.get(tr.target, -1)
            mark = ""
            if tr.target == name:
                mark = " @"
            elif 0 <= target_depth <= layer.get(name, -1):
                mark = " ^"
            guard = " ".join(tr.when.split()) or "always"
            tail = f" {ch['arrow']} {tr.target}{mark}"
            start = len(lines)
            if len(lead) + len(guard) + len(tail) <= width:
                lines.append(f"{lead}{guard}{tail}")
            else:  # a long guard: on a line of its own, the arrow under it
                lines.append(_cut(f"{lead}{guard}", width, ch["dots"]))
                lines.append(_cut(f"    {ch['arrow']} {tr.target}{mark}", width, ch["dots"]))
            arrows[(name, j)] = (start, len(lines) - 1)
    if left_out > 0:
        lines += ["", _cut(f"... and {left_out} more states, not drawn", width, ch["dots"])]
    return Diagram(tuple(lines), boxes, arrows, tuple(placed))


def state_notes(definition: FsmDefinition) -> dict[str, str]:
    """Each state's actions in a few words (``move forward_power, timer 1``), for its box."""
    out: dict[str, str] = {}
    for state in definition.states:
        parts = []
        for action in state.on_enter:
            parts.append(_ACTION_WORDS[type(action)](action))
        out[state.name] = ", ".join(parts)
    return out


_ACTION_WORDS: dict[type, Callable[[Any], str]] = {
    MoveAction: lambda a: f"move {a.power}",
    TurnAction: lambda a: f"turn {a.degrees}",
    WheelsAction: lambda a: f"wheels {a.left},{a.right}",
    MotorAction: lambda a: f"motor {a.wheel} {a.power}",
    StopAction: lambda a: "stop",
    TimerAction: lambda a: f"timer {a.seconds}",
    SetAction: lambda a: "set " + ", ".join(f"{k}={v}" for k, v in a.assignments),
}
