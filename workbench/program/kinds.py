"""VIPLE activity kinds by number (``ActivityNameInt``) and the mapping file for unknown ones.

VIPLE stores each activity's kind as a number. The numbers below are the ones real program
files and VIPLE's toolbox order establish. Services whose numbers no public file shows (Robot+
Move at Power, Robot+ Turn by Degree, Robot Motor, Custom Event) can be named by the user in a
small YAML mapping file::

    kinds:
      47: {activity: move-at-power}            # power = the incoming message
      48: {activity: turn-by-degrees, value: 0}  # degrees = the expression in Values[0]
      33: {activity: custom-event, value: 0}   # Values[0] names the activity block
      40: {activity: ignore}                   # never runs (a display-only service)

``value`` is the index of the ``Value`` holding the argument expression; without it the
incoming message is the argument (for Custom Event: the block name is then looked for in
every Value).
"""

from __future__ import annotations

import os
from dataclasses import dataclass

from workbench.files.bounded import BoundedFileError, Limits, load_yaml, read_text

INPUT_PIN = -1
OUTPUT_PIN = -2
EVENT_PIN = -3
BLOCK = 0
VARIABLE = 1
CALCULATE = 2
DATA = 3
JOIN = 4
MERGE = 5
IF = 6
SWITCH = 7
WHILE = 8
BREAK = 9
END_WHILE = 10
COMMENT = 11
KEY_PRESS = 13
TIMER = 15
ROBOT = 19
DRIVE = 20
TOUCH = 22
DISTANCE = 23
OTHER_SENSOR = 25
PRINT_LINE = 28
KEY_RELEASE = 29
CODE = 44
RAW_SENSOR = 52

#: kind number -> what the activity is, in the words of VIPLE's toolbox
KNOWN: dict[int, str] = {
    INPUT_PIN: "Input",
    OUTPUT_PIN: "Output",
    EVENT_PIN: "Event pin",
    BLOCK: "Activity Block",
    VARIABLE: "Variable",
    CALCULATE: "Calculate",
    DATA: "Data",
    JOIN: "Join",
    MERGE: "Merge",
    IF: "If",
    SWITCH: "Switch",
    WHILE: "While",
    BREAK: "Break",
    END_WHILE: "End While",
    COMMENT: "Comment",
    KEY_PRESS: "Key Press Event",
    TIMER: "Timer",
    ROBOT: "Robot",
    DRIVE: "Robot Drive",
    TOUCH: "Robot Touch Sensor",
    DISTANCE: "Robot Distance Sensor",
    OTHER_SENSOR: "Robot Sensor",
    PRINT_LINE: "Print Line",
    KEY_RELEASE: "Key Release Event",
    CODE: "Code Activity",
    RAW_SENSOR: "Robot Sensor (raw)",
}

#: what a user may name an unknown kind in a mapping file
MAPPABLE: dict[str, str] = {
    "move-at-power": "Robot+ Move at Power",
    "turn-by-degrees": "Robot+ Turn by Degree",
    "motor-left": "Robot Motor (left wheel)",
    "motor-right": "Robot Motor (right wheel)",
    "custom-event": "Custom Event",
    "ignore": "ignored service",
}

MAPPING_LIMITS = Limits("a kinds mapping file", max_bytes=64 * 1024, max_lines=2_000)
_EXAMPLE = "e.g. kinds: {47: {activity: move-at-power}}"


@dataclass(frozen=True)
class Mapped:
    """An unknown kind number named by the user: which activity, and where its argument is."""

    activity: str
    value: int | None = None

    @property
    def label(self) -> str:
        return MAPPABLE[self.activity]


KindMap = dict[int, Mapped]


def kind_label(kind: int, mapping: KindMap | None = None) -> str:
    if kind in KNOWN:
        return KNOWN[kind]
    if mapping and kind in mapping:
        return mapping[kind].label
    return "unknown"


def load_kind_map(path: str | os.PathLike) -> KindMap:
    """Read a mapping file; any problem is a :class:`BoundedFileError` naming the entry."""
    source = str(path)
    data = load_yaml(read_text(path, MAPPING_LIMITS), source, MAPPING_LIMITS)
    return parse_kind_map(data, source)


def parse_kind_map(data: object, source: str) -> KindMap:
    if not isinstance(data, dict) or set(data) != {"kinds"} or not isinstance(data["kinds"], dict):
        raise BoundedFileError(source, "the file must hold one mapping 'kinds'", _EXAMPLE)
    out: KindMap = {}
    for number, entry in data["kinds"].items():
        where = f"kinds: {number}"
        if isinstance(number, bool) or not isinstance(number, int):
            raise BoundedFileError(source, f"{where}: a kind is a whole number", _EXAMPLE)
        if number in KNOWN:
            raise BoundedFileError(
                source,
                f"{where}: kind {number} is already known ({KNOWN[number]})",
                "map only numbers the workbench reports as unknown",
            )
        if isinstance(entry, str):
            entry = {"activity": entry}
        if not isinstance(entry, dict) or not set(entry) <= {"activity", "value"}:
            raise BoundedFileError(
                source, f"{where}: give 'activity' and optionally 'value'", _EXAMPLE
            )
        activity = entry.get("activity")
        if activity not in MAPPABLE:
            raise BoundedFileError(
                source,
                f"{where}: activity {activity!r} is not one the workbench runs",
                f"use one of {', '.join(MAPPABLE)}",
            )
        value = entry.get("value")
        if value is not None and (
            isinstance(value, bool) or not isinstance(value, int) or not 0 <= value < 100
        ):
            raise BoundedFileError(
                source, f"{where}: value must be a Value index from 0 to 99", _EXAMPLE
            )
        out[number] = Mapped(activity, value)
    return out
