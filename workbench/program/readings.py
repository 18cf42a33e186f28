"""Sensor values as a program's sensor activities deliver them.

A robot reports any JSON scalar: a number, text (an AI camera's ``"straight"``), true/false or
null. The Distance, Touch and other sensor activities (kinds 23, 22, 25) are VIPLE's numeric
sensors: a number reaches the program as it came, and so does numeric text, as its number (the
Unity simulator sent ``"1.734"``, and ``value < 30`` must still compare two numbers). Any other
value reaches the program as it came, so a program can steer by text (``value == "straight"``).
The raw Robot Sensor (kind 52) is given the report's own text instead (see the interpreter).
"""

from __future__ import annotations

import math
import re

from .viple_expr import Value, show

#: a number as JSON writes it, between JSON blanks (no NaN, no Infinity)
_NUMBER_TEXT = re.compile(r"[ \t\r\n]*([+-]?(?:[0-9]+(?:\.[0-9]*)?|\.[0-9]+)(?:[eE][+-]?[0-9]+)?)"
                          r"[ \t\r\n]*")  # fmt: skip


def numeric_text(text: str) -> float | None:
    """The number ``text`` holds (JSON blanks around it allowed), or None: not a finite
    number."""
    match = _NUMBER_TEXT.fullmatch(text)
    if match is None:
        return None
    number = float(match.group(1))
    return number if math.isfinite(number) else None


def sensor_message(value: Value) -> Value:
    """What a numeric sensor activity sends on for a reading: numeric text as its number,
    anything else as it came."""
    if isinstance(value, str):
        number = numeric_text(value)
        return value if number is None else number
    return value


def pressed(value: Value) -> bool | None:
    """Whether a touch reading says pressed (a non-zero number, true, ``"true"``); None when
    it says neither pressed nor released (other text, null)."""
    if isinstance(value, bool):
        return value
    if isinstance(value, int | float):
        return value != 0
    if isinstance(value, str) and value.strip().lower() in ("true", "false"):
        return value.strip().lower() == "true"
    return None


def touch_problem(port: int, value: Value) -> str:
    """The run-time error for a touch reading that says neither pressed nor released."""
    shown = "null" if value is None else repr(show(value)[:30])
    return f"the touch sensor on port {port} reported {shown}: expected 0 or 1 (or true/false)"
