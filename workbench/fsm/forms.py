"""The FSM editor's forms: a new file, a state added, a transition added, as edits of the text.

A student who does not know YAML fills in a form; what it writes is YAML lines added to the
file's text, so the text stays the one thing the student sees and saves (their own lines,
comments and layout are left as they are). Each edit is read back through the FSM loader's
YAML reader before it is given: an edit that would not read back as the new state or
transition (the file is written in a form the edit cannot extend, such as ``states: {}`` on
one line) is refused with :class:`FormError`, saying how to add it by typing instead.
"""

from __future__ import annotations

import json
import re
from collections.abc import Sequence
from dataclasses import dataclass

import yaml
from yaml.nodes import MappingNode, Node, ScalarNode, SequenceNode

from workbench.files.bounded import FSM_LIMITS, BoundedFileError, check_text, compose_yaml
from workbench.sim.sensors import SensorSpec

from .yaml_file import ACTIONS

_NAME = re.compile(r"[A-Za-z_][A-Za-z0-9_]*")
#: the top-level key a line starts, at column 0
_TOP_KEY = re.compile(r"^([A-Za-z_][A-Za-z0-9_]*)\s*:")


class FormError(ValueError):
    """A form's entry that cannot be written; the message says what to change."""


@dataclass(frozen=True)
class Edited:
    """A form's edit: the whole new text, and the line (from 0) the edit begins on."""

    text: str
    line: int


def new_text(name: str, sensors: Sequence[SensorSpec], profile: str) -> str:
    """A new FSM file for the robot's ``sensors``: each read by its mount's name
    (``front``, ``right``...), with no states yet."""
    lines = [f"name: {_scalar(name or 'my-fsm')}", "", "sensors:"]
    seen: set[str] = set()
    for spec in sensors:
        reader = spec.mount if spec.mount not in seen else f"{spec.mount}_{spec.port}"
        seen.add(reader)
        lines.append(f"  {reader}: {{kind: {spec.kind}, mount: {spec.mount}, port: {spec.port}}}")
    if not seen:
        lines[-1] = "sensors: {}"
    lines += ["", "states:", ""]
    return "\n".join(lines)


def _scalar(text: str) -> str:
    """``text`` as a YAML value that reads back as itself (or as the number it is)."""
    text = " ".join(text.split())
    try:
        back = yaml.safe_load(text) if text else None
    except yaml.YAMLError:
        back = None
    if back == text or (isinstance(back, int | float) and not isinstance(back, bool)):
        return text
    if isinstance(back, bool) and text in ("True", "False"):
        return text
    return json.dumps(text)


def _name(text: str, what: str) -> str:
    text = text.strip()
    if not _NAME.fullmatch(text):
        raise FormError(
            f"{what} {text!r} is not a name: use letters, digits and _, not starting with a digit"
            if text
            else f"give the {what}"
        )
    return text


def parse_actions(text: str) -> list[tuple[str, str]]:
    """``move: 1; timer: 2`` -> ``[("move", "1"), ("timer", "2")]``; ``stop`` takes no value.
    Each action is ``KIND: VALUE``, separated by ``;`` (``wheels: 0.5, 0.5`` for two
    powers, ``set: x = front`` for an assignment)."""
    out = []
    for part in (p.strip() for p in text.split(";")):
        if not part:
            continue
        kind, colon, value = part.partition(":")
        kind = kind.strip()
        if kind == "stop" and not value.strip():
            out.append(("stop", ""))
            continue
        if kind not in ACTIONS or not colon or not value.strip():
            raise FormError(
                f"{part!r} is not an action: write KIND: VALUE with KIND one of "
                f"{', '.join(ACTIONS)}, e.g. 'move: 1.0; timer: 2'"
            )
        out.append((kind, value.strip()))
    return out


def parse_sets(text: str) -> list[tuple[str, str]]:
    """``turns = turns + 1; x = front`` -> ``[("turns", "turns + 1"), ("x", "front")]``."""
    out = []
    for part in (p.strip() for p in text.split(";")):
        if not part:
            continue
        var, eq, value = part.partition("=")
        if not eq or not value.strip() or value.startswith("="):
            raise FormError(f"{part!r} is not an assignment: write NAME = VALUE, e.g. turns = 0")
        out.append((_name(var, "variable"), value.strip()))
    return out


def _action_line(kind: str, value: str) -> str:
    if kind == "stop":
        return "- stop"
    if kind == "wheels":
        left, comma, right = value.strip("[] ").partition(",")
        if not comma:
            raise FormError("wheels takes two powers: write e.g. 'wheels: 0.5, 0.5'")
        return f"- wheels: [{_scalar(left)}, {_scalar(right)}]"
    if kind == "motor":
        wheel, _, power = value.strip("{} ").partition(" ")
        if wheel not in ("left", "right") or not power.strip():
            raise FormError("motor takes a wheel and a power: write e.g. 'motor: left 0.3'")
        return f"- motor: {{wheel: {wheel}, power: {_scalar(power)}}}"
    if kind == "set":
        pairs = parse_sets(value)
        return "- set: {" + ", ".join(f"{k}: {_scalar(v)}" for k, v in pairs) + "}"
    return f"- {kind}: {_scalar(value)}"


def _compose(text: str) -> MappingNode | None:
    try:
        root = compose_yaml(check_text(text, "<form>", FSM_LIMITS), "<form>", FSM_LIMITS)
    except (BoundedFileError, yaml.YAMLError):
        return None
    return root if isinstance(root, MappingNode) else None


def _get(node: Node | None, key: str) -> Node | None:
    if not isinstance(node, MappingNode):
        return None
    for k, v in node.value:
        if isinstance(k, ScalarNode) and k.value == key:
            return v
    return None


_TYPE_IT = "add it by typing, or fix the file's problems first"


def _lines(text: str) -> list[str]:
    return text.split("\n")


def _block_end(lines: list[str], start: int, indent: int) -> int:
    """The line after the block that begins at ``start`` (its lines indented more than
    ``indent``; blank lines and comments inside it belong to it)."""
    end = start + 1
    last = start + 1
    while end < len(lines):
        line = lines[end]
        stripped = line.strip()
        if stripped and not stripped.startswith("#"):
            if len(line) - len(line.lstrip(" ")) <= indent:
                break
            last = end + 1
        end += 1
    return last


def _states_line(lines: list[str]) -> int | None:
    for i, line in enumerate(lines):
        match = _TOP_KEY.match(line)
        if match and match.group(1) == "states":
            return i
    return None


def _child_indent(lines: list[str], start: int, end: int, parent: int) -> int:
    for line in lines[start + 1 : end]:
        if line.strip() and not line.strip().startswith("#"):
            return len(line) - len(line.lstrip(" "))
    return parent + 2


def add_state(text: str, name: str, actions: str = "", description: str = "") -> Edited:
    """``text`` with a new state ``name`` at the end of ``states:`` (``actions`` as
    :func:`parse_actions` reads them); the first state becomes the initial one when the file
    names none."""
    name = _name(name, "state name")
    items = [_action_line(k, v) for k, v in parse_actions(actions)]
    root = _compose(text) if text.strip() else MappingNode("tag:yaml.org,2002:map", [])
    if root is None:
        raise FormError(f"the file cannot be read as YAML now: {_TYPE_IT}")
    states = _get(root, "states")
    if isinstance(states, MappingNode) and any(k.value == name for k, _ in states.value):
        raise FormError(f"a state {name!r} exists already: choose another name")
    lines = _lines(text.rstrip("\n")) if text.strip() else []
    at = _states_line(lines)
    if at is None:
        lines += ["", "states:"]
        at = len(lines) - 1
    elif lines[at].split(":", 1)[1].split("#")[0].strip():
        raise FormError(f"states: is written on one line: {_TYPE_IT}")
    end = _block_end(lines, at, 0)
    indent = _child_indent(lines, at, end, 0)
    pad = " " * indent
    block = [f"{pad}{name}:"]
    if description.strip():
        block.append(f"{pad}  description: {_scalar(description)}")
    if items:
        block.append(f"{pad}  on_enter:")
        block += [f"{pad}    {item}" for item in items]
    else:
        block.append(f"{pad}  on_enter: []")
    block.append(f"{pad}  transitions: []")
    while end > at + 1 and not lines[end - 1].strip():
        end -= 1
    gap = [""] if end > at + 1 else []
    new = lines[:end] + gap + block + lines[end:]
    if _get(root, "initial") is None:
        new = [*new[:at], f"initial: {name}", "", *new[at:]]
    out = "\n".join(new).strip("\n") + "\n"
    _must_have(out, name, None)
    return Edited(out, _lines(out).index(block[0]))


def add_transition(text: str, source: str, target: str, when: str = "", sets: str = "") -> Edited:
    """``text`` with a transition from ``source`` to ``target`` added after the source's
    others (it is checked last); ``when`` is its guard ("" fires at the next tick), ``sets``
    its assignments (:func:`parse_sets`)."""
    source = _name(source, "from state")
    target = _name(target, "to state")
    pairs = parse_sets(sets)
    root = _compose(text)
    if root is None:
        raise FormError(f"the file cannot be read as YAML now: {_TYPE_IT}")
    states = _get(root, "states")
    state = _get(states, source)
    if state is None:
        raise FormError(f"there is no state {source!r} yet: add it first")
    if _get(states, target) is None:
        raise FormError(f"there is no state {target!r} yet: add it first")
    if not isinstance(state, MappingNode) or state.flow_style:
        raise FormError(f"state {source} is written on one line: {_TYPE_IT}")
    before = len(_transitions(state))
    fields = []
    if when.strip():
        fields.append(f"when: {_scalar(when)}")
    fields.append(f"to: {target}")
    if pairs:
        fields.append("set: {" + ", ".join(f"{k}: {_scalar(v)}" for k, v in pairs) + "}")
    item = "- {" + ", ".join(fields) + "}"
    lines = _lines(text.rstrip("\n"))
    key_line = _key_line(states, source)
    indent = len(lines[key_line]) - len(lines[key_line].lstrip(" "))
    end = _block_end(lines, key_line, indent)
    trs = _get(state, "transitions")
    if trs is None:
        new = [*lines[:end], f"{' ' * (indent + 2)}transitions:", f"{' ' * (indent + 4)}{item}"]
        new += lines[end:]
        first = end
    elif isinstance(trs, SequenceNode) and trs.flow_style and not trs.value:
        row = trs.start_mark.line
        line = lines[row]
        lines[row] = line[: trs.start_mark.column].rstrip() + line[trs.end_mark.column :]
        new = [*lines[: row + 1], f"{' ' * (indent + 4)}{item}", *lines[row + 1 :]]
        first = row + 1
    elif isinstance(trs, SequenceNode) and not trs.flow_style:
        last = trs.value[-1]
        pad = last.start_mark.column - 2
        stop = _block_end(lines, last.start_mark.line, pad)
        stop = min(stop, end)
        new = [*lines[:stop], f"{' ' * pad}{item}", *lines[stop:]]
        first = stop
    else:
        raise FormError(f"the transitions of {source} are written on one line: {_TYPE_IT}")
    out = "\n".join(new).rstrip("\n") + "\n"
    _must_have(out, source, before + 1)
    return Edited(out, first)


def _transitions(state: MappingNode) -> list[Node]:
    trs = _get(state, "transitions")
    return list(trs.value) if isinstance(trs, SequenceNode) else []


def _key_line(states: Node | None, name: str) -> int:
    assert isinstance(states, MappingNode)
    for k, _v in states.value:
        if k.value == name:
            return int(k.start_mark.line)
    raise FormError(f"there is no state {name!r}")


def _must_have(text: str, state: str, transitions: int | None) -> None:
    """The edit reads back with ``state`` (and that many transitions), or it is refused."""
    root = _compose(text)
    node = _get(_get(root, "states"), state)
    ok = isinstance(node, MappingNode)
    if ok and transitions is not None:
        assert isinstance(node, MappingNode)
        ok = len(_transitions(node)) == transitions
    if not ok:
        raise FormError(f"the file is laid out in a way this form cannot extend: {_TYPE_IT}")
