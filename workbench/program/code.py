"""Code Activities (kind 44): user C# the workbench never compiles or runs.

One body is common in course programs: it parses the raw sensor JSON a Robot Sensor (kind 52)
delivers, ``{"sensors":[{"name":..,"id":..,"value":..}]}``, and returns ``sensors[0].value``.
That body is recognised by its shape (a JSON parse of ``Input``, then ``sensors``, index 0 and
``value``, assigned to ``Output``) and run as a built-in. Any other body stops the load.
"""

from __future__ import annotations

import json
import re

from .viple_expr import Value

MAX_JSON = 64 * 1024

_COMMENTS = re.compile(r"//[^\n]*|/\*.*?\*/", re.S)
_PARSE_CALLS = re.compile(
    r"(JObject|JToken|JArray|JsonDocument)\s*\.\s*Parse\s*\(|JsonConvert\s*\.\s*Deserialize"
    r"(Object)?\s*(<[^>]*>)?\s*\(|\.\s*Deserialize(Object)?\s*(<[^>]*>)?\s*\(|DeserializeObject",
)
_SENSORS_FIRST_VALUE = re.compile(
    r"""(\[\s*"sensors"\s*\]|\.\s*sensors\b|GetProperty\s*\(\s*"sensors"\s*\))"""
    r"""\s*(\[\s*0\s*\]|\.\s*First\s*\(\s*\)|\.\s*ElementAt\s*\(\s*0\s*\))"""
    r"""\s*(\[\s*"value"\s*\]|\.\s*value\b|\.\s*GetProperty\s*\(\s*"value"\s*\))""",
    re.I,
)


class CodeRefused(ValueError):
    """A Code Activity whose body the workbench does not run."""


def class_name(values: tuple[str, ...]) -> str:
    return values[0].strip() if values and values[0].strip() else "(unnamed)"


def recognise(values: tuple[str, ...]) -> str:
    """The built-in a Code Activity's body matches ("first-sensor-value"), else CodeRefused."""
    source = _COMMENTS.sub(" ", values[1] if len(values) > 1 else "")
    if (
        "Execute" in source
        and re.search(r"\bInput\b", source)
        and re.search(r"\bOutput\s*=", source)
        and _PARSE_CALLS.search(source)
        and _SENSORS_FIRST_VALUE.search(source)
    ):
        return "first-sensor-value"
    raise CodeRefused(
        f"the C# class {class_name(values)[:40]!r} is not run: the workbench never compiles C#, "
        "and runs only the common body that parses the sensor JSON and returns "
        "sensors[0].value"
    )


def first_sensor_value(message: Value) -> Value:
    """``sensors[0].value`` of a raw sensor report (a JSON text)."""
    if not isinstance(message, str):
        raise ValueError("the Code Activity expects the sensor JSON text as its input")
    if len(message) > MAX_JSON:
        raise ValueError("the sensor JSON is too long")
    try:
        data = json.loads(message)
        value = data["sensors"][0]["value"]
    except (ValueError, KeyError, IndexError, TypeError):
        raise ValueError("the input is not sensor JSON with a first sensor value") from None
    if isinstance(value, bool) or not isinstance(value, int | float | str):
        raise ValueError("the first sensor's value is not a number or text")
    return value
