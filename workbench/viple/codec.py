"""VIPLE's JSON robot protocol: line framing, commands in, sensor reports out.

The wire format is described in PROTOCOL.md. This module only turns bytes and text into
commands and readings (and back); the servers that carry them are built on top of it.

Receiver choices where the protocol leaves room:

* A single wheel entry whose ``servoId`` matches neither wheel port drives the left wheel
  (the array-order rule: first entry = left).
* When at least one ``servoId`` matches a wheel port, entries matching neither port are ignored
  (they may belong to other motors); two entries for the same wheel port are rejected.
* More than two wheel entries with no matching ``servoId`` are rejected as ambiguous.
* Robot+ entries (``servoId`` -1 or missing) and wheel entries in one message are all applied,
  in array order; the wheel entries together make one command, placed at the first of them.
* ``isTurn`` only matters for Robot+ entries, but a malformed ``isTurn`` is rejected anywhere.
* ``servoId`` and sensor ``id`` may be whole numbers written as numbers or strings ("3", 3.0);
  negative ports other than -1 are rejected.
* A sensor ``value`` may be any JSON scalar and is read as sent (text stays text); only a
  reader that needs a number converts numeric text, as VIPLE does with the Unity simulator's.

Every line that is not a message is refused with ``CodecError`` and nothing else: its reason
says where (the field path, ``servos[0].servoSpeed``), what was wrong and what is expected.
Number strings hold only a JSON-style number between JSON blanks (no control characters, no
NaN or Infinity, nothing that overflows a float); an object that names a key twice is refused
rather than keeping one of the two values.
"""

from __future__ import annotations

import json
import math
import re
from collections.abc import Iterable
from dataclasses import dataclass
from typing import Any

from workbench.sim.commands import (
    Command,
    MotorPower,
    MoveAtPower,
    Stop,
    TurnByDegrees,
    WheelPowers,
)
from workbench.sim.sensor_kinds import ReportForm, is_kind, sensor_kind

#: sensor names VIPLE understands in a report (the kinds the workbench simulates, and how a
#: report writes each, are the table of :mod:`workbench.sim.sensor_kinds`)
REPORT_KINDS = ("distance", "touch", "light", "sound", "color", "motorEncoder")
#: the ``servoId`` of VIPLE's Robot+ services (Move at Power, Turn by Degree)
ROBOT_PLUS_ID = -1
DEFAULT_MAX_LINE_BYTES = 65536
#: a sensor's value as a report carries it: a number, text, true/false or null
SensorValue = float | str | bool | None

_NUMBER_TEXT = re.compile(r"[+-]?(?:[0-9]+(?:\.[0-9]*)?|\.[0-9]+)(?:[eE][+-]?[0-9]+)?")
_LONGEST_EXACT_INT = 18
_SHOWN_CHARS = 40
_JSON_SPACE = " \t\r\n"
_BOM = "\ufeff"


class CodecError(ValueError):
    """Input that is not a message of the VIPLE protocol, with a human-readable reason."""

    def __init__(self, reason: str, line_no: int | None = None) -> None:
        self.reason = reason
        self.line_no = line_no
        super().__init__(reason if line_no is None else f"line {line_no}: {reason}")

    def at_line(self, line_no: int | None) -> CodecError:
        return CodecError(self.reason, line_no)


class FrameError(CodecError):
    """Raised by ``LineSplitter.feed`` for lines it had to drop.

    ``lines`` holds the good lines of the same read, in order: handle them as if ``feed`` had
    returned them. ``reasons`` lists every dropped line's reason.
    """

    def __init__(self, reasons: list[str], lines: list[str]) -> None:
        self.reasons = list(reasons)
        self.lines = list(lines)
        super().__init__("; ".join(reasons))


class FrameTooLong(FrameError):
    """A line (or the unfinished line still being received) is longer than the limit."""


class NotUtf8(FrameError):
    """A line whose bytes are not valid UTF-8."""


# ---------------------------------------------------------------------------------------------
# Framing


_Problems = list[tuple[type[FrameError], str]]


class LineSplitter:
    """Cuts a TCP byte stream into text lines (``\\r\\n`` or ``\\n``), skipping blank lines.

    At most ``max_bytes`` bytes of an unfinished line are kept (plus a trailing ``\\r``). A longer
    line is dropped up to its line end and reported with ``FrameTooLong``; a line that is not
    UTF-8 is dropped and reported with ``NotUtf8``. Other lines of the same read are not lost:
    they are in the error's ``lines``.
    """

    def __init__(self, max_bytes: int = DEFAULT_MAX_LINE_BYTES) -> None:
        if isinstance(max_bytes, bool) or not isinstance(max_bytes, int) or max_bytes < 1:
            raise ValueError(f"max_bytes must be a positive whole number, not {max_bytes!r}")
        self.max_bytes = max_bytes
        self._pending = bytearray()
        self._discarding = False

    @property
    def pending_bytes(self) -> int:
        """How many bytes of an unfinished line are being held."""
        return len(self._pending)

    def feed(self, data: bytes) -> list[str]:
        """The lines completed by ``data``, without line ends or surrounding blanks.

        Raises ``FrameTooLong`` or ``NotUtf8`` (both ``FrameError``) when a line had to be
        dropped; the error then carries this read's good lines and every reason.
        """
        lines: list[str] = []
        problems: _Problems = []
        start = 0
        while (end := data.find(b"\n", start)) >= 0:
            self._finish_line(data[start:end], lines, problems)
            start = end + 1
        self._keep_unfinished(data[start:], problems)
        if problems:
            kind = problems[0][0]
            raise kind([reason for _, reason in problems], lines)
        return lines

    def _finish_line(self, tail: bytes, lines: list[str], problems: _Problems) -> None:
        if self._discarding:
            self._discarding = False
            return
        ends_with_cr = tail.endswith(b"\r") if tail else self._pending.endswith(b"\r")
        size = len(self._pending) + len(tail) - ends_with_cr
        if size > self.max_bytes:
            self._pending.clear()
            problems.append(
                (
                    FrameTooLong,
                    f"line of {size} bytes is longer than the limit of {self.max_bytes} bytes;"
                    " it was dropped",
                )
            )
            return
        raw = (bytes(self._pending) + tail)[:size]
        self._pending.clear()
        try:
            text = raw.decode("utf-8")
        except UnicodeDecodeError as err:
            problems.append((NotUtf8, _utf8_reason(raw, err)))
            return
        text = text.strip(_JSON_SPACE)
        if text:
            lines.append(text)

    def _keep_unfinished(self, rest: bytes, problems: _Problems) -> None:
        if self._discarding or not rest:
            return
        size = len(self._pending) + len(rest)
        if size - rest.endswith(b"\r") > self.max_bytes:
            self._pending.clear()
            self._discarding = True
            problems.append(
                (
                    FrameTooLong,
                    f"unfinished line of {size} bytes is already longer than the limit of "
                    f"{self.max_bytes} bytes; dropping it up to its line end",
                )
            )
            return
        self._pending += rest


def _utf8_reason(raw: bytes, err: UnicodeDecodeError) -> str:
    bad = " ".join(f"0x{byte:02x}" for byte in raw[err.start : err.end])
    return f"line is not UTF-8 text at byte {err.start + 1} ({bad}: {err.reason}); it was dropped"


def split_frame(text: str) -> list[str]:
    """The JSON objects in one WebSocket text frame: usually one, or several on separate lines."""
    parts = (part.strip(_JSON_SPACE) for part in text.split("\n"))
    return [part for part in parts if part]


# ---------------------------------------------------------------------------------------------
# JSON values


@dataclass(frozen=True)
class _OutOfRange:
    """A JSON number too large for a float; kept as text so errors can show it."""

    text: str


class _NotJsonConstant(ValueError):
    pass


class _RepeatedKeys(dict):
    """A JSON object that named a key more than once (``json`` would keep only the last)."""

    repeated: str = ""


def _object_of(pairs: list[tuple[str, Any]]) -> dict[str, Any]:
    obj = dict(pairs)
    if len(obj) == len(pairs):
        return obj
    seen: set[str] = set()
    repeated = ""
    for key, _ in pairs:
        if key in seen:
            repeated = key
            break
        seen.add(key)
    flagged = _RepeatedKeys(obj)
    flagged.repeated = repeated
    return flagged


def _parse_float(text: str) -> float | _OutOfRange:
    value = float(text)
    return value if math.isfinite(value) else _OutOfRange(text)


def _parse_int(text: str) -> int | float | _OutOfRange:
    if len(text) <= _LONGEST_EXACT_INT:
        return int(text)
    return _parse_float(text)


def _reject_constant(name: str) -> None:
    raise _NotJsonConstant(f"{name} is not a JSON value")


def _load(line: str) -> Any:
    text = line.strip(_JSON_SPACE).removeprefix(_BOM)
    if not text:
        raise CodecError("not JSON: the line is empty")
    try:
        return json.loads(
            text,
            parse_float=_parse_float,
            parse_int=_parse_int,
            parse_constant=_reject_constant,
            object_pairs_hook=_object_of,
        )
    except json.JSONDecodeError as err:
        raise CodecError(f"not JSON: {err.msg} at column {err.colno}") from None
    except _NotJsonConstant as err:
        raise CodecError(f"not JSON: {err}") from None
    except RecursionError:
        raise CodecError("not JSON: nested too deeply to read") from None


def _kind_of(value: Any) -> str:
    if isinstance(value, bool):
        return "true/false"
    if value is None:
        return "null"
    if isinstance(value, dict):
        return "an object"
    if isinstance(value, list):
        return "a list"
    if isinstance(value, str):
        return "a string"
    return "a number"


def _show(value: Any) -> str:
    """A short, printable rendering of a scalar JSON value for an error message."""
    if isinstance(value, _OutOfRange):
        text = value.text
    elif isinstance(value, dict | list):
        return _kind_of(value)
    else:
        text = json.dumps(value, ensure_ascii=False)
        if not text.isprintable() or _has_surrogates(text):
            text = json.dumps(value)
    if len(text) > _SHOWN_CHARS:
        text = text[: _SHOWN_CHARS - 1] + "…"
    return text


def _has_surrogates(text: str) -> bool:
    try:
        text.encode("utf-8")
    except UnicodeEncodeError:
        return True
    return False


_A_NUMBER = "a number like 0.5, or a string holding one"


def _number(value: Any, path: str, expected: str = _A_NUMBER) -> float:
    """A finite number given as a JSON number or a numeric string (JSON blanks around it)."""
    if isinstance(value, _OutOfRange):
        raise CodecError(f"{path} {_show(value)} is out of range; expected a finite number")
    if isinstance(value, bool) or value is None or isinstance(value, dict | list):
        raise CodecError(f"{path} is {_kind_of(value)}; expected {expected}")
    if isinstance(value, str):
        text = value.strip(_JSON_SPACE)
        if not _NUMBER_TEXT.fullmatch(text):
            raise CodecError(f"{path} {_show(value)} is not a number; expected {expected}")
        number = float(text)
        if not math.isfinite(number):
            raise CodecError(f"{path} {_show(value)} is out of range; expected a finite number")
        return number
    return float(value)


def _port(value: Any, path: str, expected: str) -> int:
    number = _number(value, path, expected)
    if not number.is_integer():
        raise CodecError(f"{path} {_show(value)} is not a whole number; expected {expected}")
    return int(number)


def _flag(value: Any, path: str) -> bool:
    if value is None:
        return False
    if isinstance(value, bool):
        return value
    if isinstance(value, str) and value.strip(_JSON_SPACE).lower() in ("true", "false"):
        return value.strip(_JSON_SPACE).lower() == "true"
    raise CodecError(
        f'{path} {_show(value)} is not true or false; expected true, false, "true" or "false"'
    )


def _object_list(message: Any, key: str) -> list[Any]:
    if not isinstance(message, dict):
        raise CodecError(f'expected a JSON object with "{key}", got {_kind_of(message)}')
    _check_keys_once(message, "the message")
    if key not in message:
        keys = ", ".join(_show(k) for k in list(message)[:5])
        found = f"an object with keys {keys}" if keys else "an empty object"
        raise CodecError(f'expected a JSON object with "{key}", got {found}')
    items = message[key]
    if not isinstance(items, list):
        raise CodecError(f"{key} is {_kind_of(items)}; expected a list of entries")
    return items


def _entry_object(item: Any, path: str, example: str) -> dict[str, Any]:
    if not isinstance(item, dict):
        raise CodecError(f"{path} is {_kind_of(item)}; expected an object like {example}")
    _check_keys_once(item, path)
    return item


def _check_keys_once(obj: dict[str, Any], path: str) -> None:
    if isinstance(obj, _RepeatedKeys):
        raise CodecError(
            f"{path} has the key {_show(obj.repeated)} more than once; expected each key once"
        )


# ---------------------------------------------------------------------------------------------
# Commands


@dataclass(frozen=True)
class WheelPorts:
    """The ports the student gave VIPLE's Robot Drive service for the left and right wheel."""

    left: int
    right: int

    def __post_init__(self) -> None:
        for side in ("left", "right"):
            port = getattr(self, side)
            if isinstance(port, bool) or not isinstance(port, int) or port < 0:
                raise ValueError(f"{side} wheel port must be a whole number >= 0, not {port!r}")
        if self.left == self.right:
            raise ValueError(f"left and right wheel need different ports, both are {self.left}")

    def wheel_of(self, servo_id: int) -> str | None:
        if servo_id == self.left:
            return "left"
        if servo_id == self.right:
            return "right"
        return None


@dataclass(frozen=True)
class _Servo:
    """One entry of a "servos" array; ``servo_id`` None means the Robot+ services."""

    index: int
    servo_id: int | None
    is_turn: bool
    speed: float


def parse_command(line: str, wheels: WheelPorts, line_no: int | None = None) -> list[Command]:
    """The commands in one VIPLE message line, in the order to apply them.

    Raises ``CodecError`` (and nothing else) for any line that is not such a message.
    """
    try:
        items = _object_list(_load(line), "servos")
        if not items:
            raise CodecError("servos is empty; expected at least one entry")
        servos = [_servo(item, index) for index, item in enumerate(items)]
        return _commands(servos, wheels)
    except CodecError as err:
        raise err.at_line(line_no) from None


_SERVO_EXAMPLE = '{"servoId":3,"servoSpeed":0.5}'
_PORT_OR_ROBOT_PLUS = "a port number like 3, or -1 for the Robot+ services"


def _servo(item: Any, index: int) -> _Servo:
    path = f"servos[{index}]"
    entry = _entry_object(item, path, _SERVO_EXAMPLE)
    servo_id = _servo_id(entry.get("servoId"), f"{path}.servoId")
    is_turn = _flag(entry.get("isTurn"), f"{path}.isTurn")
    if "servoSpeed" not in entry:
        raise CodecError(f"{path}.servoSpeed is missing; expected {_A_NUMBER}")
    speed = _number(entry["servoSpeed"], f"{path}.servoSpeed")
    return _Servo(index, servo_id, is_turn, speed)


def _servo_id(value: Any, path: str) -> int | None:
    if value is None:
        return None
    port = _port(value, path, _PORT_OR_ROBOT_PLUS)
    if port == ROBOT_PLUS_ID:
        return None
    if port < 0:
        raise CodecError(f"{path} {port} is not a port; expected {_PORT_OR_ROBOT_PLUS}")
    return port


def _commands(servos: list[_Servo], wheels: WheelPorts) -> list[Command]:
    wheel_servos = [s for s in servos if s.servo_id is not None]
    wheel_command = _wheel_command(wheel_servos, wheels) if wheel_servos else None
    commands: list[Command] = []
    for servo in servos:
        if servo.servo_id is None:
            commands.append(_robot_plus_command(servo))
        elif wheel_command is not None and servo is wheel_servos[0]:
            commands.append(wheel_command)
    return commands


def _robot_plus_command(servo: _Servo) -> Command:
    if servo.is_turn:
        return TurnByDegrees(servo.speed)
    return MoveAtPower(servo.speed)


def _wheel_command(servos: list[_Servo], wheels: WheelPorts) -> Command:
    by_wheel = _match_wheels(servos, wheels)
    if not by_wheel:
        by_wheel = _in_array_order(servos, wheels)
    if len(by_wheel) == 2:
        return WheelPowers(by_wheel["left"], by_wheel["right"])
    ((wheel, power),) = by_wheel.items()
    return MotorPower(wheel, power)


def _match_wheels(servos: list[_Servo], wheels: WheelPorts) -> dict[str, float]:
    by_wheel: dict[str, float] = {}
    for servo in servos:
        wheel = wheels.wheel_of(servo.servo_id) if servo.servo_id is not None else None
        if wheel is None:
            continue
        if wheel in by_wheel:
            raise CodecError(
                f"servos[{servo.index}].servoId {servo.servo_id} is the {wheel} wheel again; "
                "expected one entry per wheel"
            )
        by_wheel[wheel] = servo.speed
    return by_wheel


def _in_array_order(servos: list[_Servo], wheels: WheelPorts) -> dict[str, float]:
    if len(servos) > 2:
        ids = ", ".join(_show(s.servo_id) for s in servos[:5]) + (", …" if len(servos) > 5 else "")
        raise CodecError(
            f"servos has {len(servos)} wheel entries (servoId {ids}) and none matches the wheel "
            f"ports; expected the left ({wheels.left}) and right ({wheels.right}) wheel ports"
        )
    return dict(zip(("left", "right"), (s.speed for s in servos), strict=False))


def encode_command(cmd: Command, wheels: WheelPorts) -> str:
    """The message VIPLE would send for ``cmd`` (keys in VIPLE's alphabetical order)."""
    if isinstance(cmd, Stop):
        cmd = WheelPowers(0.0, 0.0)
    if isinstance(cmd, WheelPowers):
        entries = [(False, wheels.left, cmd.left), (False, wheels.right, cmd.right)]
    elif isinstance(cmd, MotorPower):
        port = wheels.left if cmd.wheel == "left" else wheels.right
        entries = [(False, port, cmd.power)]
    elif isinstance(cmd, MoveAtPower):
        entries = [(False, ROBOT_PLUS_ID, cmd.power)]
    elif isinstance(cmd, TurnByDegrees):
        entries = [(True, ROBOT_PLUS_ID, cmd.degrees)]
    else:
        raise TypeError(f"not a motor command: {cmd!r}")
    body = ",".join(_servo_json(is_turn, port, speed) for is_turn, port, speed in entries)
    return '{"servos":[' + body + "]}"


def _servo_json(is_turn: bool, port: int, speed: float) -> str:
    turn = "true" if is_turn else "false"
    return f'{{"isTurn":{turn},"servoId":{port},"servoSpeed":{_format_number(speed, 6)}}}'


# ---------------------------------------------------------------------------------------------
# Sensor reports


def _format_number(value: float, places: int) -> str:
    """A JSON number with at most ``places`` decimals, never in exponent notation."""
    if isinstance(value, bool) or not math.isfinite(value):
        raise ValueError(f"cannot send {value!r} as a number")
    text = f"{value:.{places}f}".rstrip("0").rstrip(".")
    return "0" if text in ("-0", "") else text


def encode_report(readings: dict[int, float | int], kinds: dict[int, str]) -> str:
    """One sensor report carrying every configured sensor (``kinds``: port -> name)."""
    _check_report_ports(readings, kinds)
    entries = (_reading_json(port, kinds[port], readings[port]) for port in sorted(kinds))
    return '{"sensors":[' + ",".join(entries) + "]}"


def _check_report_ports(readings: dict[int, float | int], kinds: dict[int, str]) -> None:
    missing = sorted(set(kinds) - set(readings))
    if missing:
        raise ValueError(f"no reading for the sensor on port {missing[0]}")
    extra = sorted(set(readings) - set(kinds))
    if extra:
        raise ValueError(f"reading for port {extra[0]}, where no sensor is configured")


def report_form(kind: str) -> ReportForm:
    """How a report writes a sensor of ``kind``: as the sensor kinds' table says for the kinds
    the workbench simulates, as a number for the other names VIPLE knows."""
    if is_kind(kind):
        return sensor_kind(kind).report
    if kind in REPORT_KINDS:
        return ReportForm(kind)
    raise ValueError(f"unknown sensor kind {kind!r}")


def _reading_json(port: int, kind: str, value: float | int) -> str:
    try:
        form = report_form(kind)
    except ValueError as err:
        raise ValueError(f"{err} on port {port}") from None
    if isinstance(port, bool) or not isinstance(port, int) or port < 0:
        raise ValueError(f"sensor port must be a whole number >= 0, not {port!r}")
    if form.binary:
        number = "1" if value else "0"
    else:
        try:
            number = _format_number(value, form.places)
        except ValueError as err:
            raise ValueError(f"{kind} sensor on port {port}: {err}") from None
    return f'{{"name":"{form.name}","id":{port},"value":{number}}}'


def parse_report(line: str, line_no: int | None = None) -> dict[int, SensorValue]:
    """The readings (port -> value) in one sensor report, in the report's order, as a
    VIPLE-side client reads it.

    Values stay as sent: a number (as a float), text, true/false or null. A robot's own
    middleware may report text (an AI camera's ``"straight"``), and the Unity simulator sent
    its numbers as text; whoever needs a number converts numeric text (:func:`reading_number`).
    Refused: a value that is a list or an object, a number too large for a float, text holding
    a control character or a lone surrogate (nothing that could reach a terminal raw).
    """
    try:
        items = _object_list(_load(line), "sensors")
        return _readings(items)
    except CodecError as err:
        raise err.at_line(line_no) from None


def reading_number(value: SensorValue, port: int) -> float:
    """A reading as a number, for a reader that needs one (an FSM's guards): a number as it
    is, numeric text converted; ``CodecError`` naming the port for anything else."""
    return _number(value, f"the reading of port {port}", "a number, or text holding one")


def _readings(items: Iterable[Any]) -> dict[int, SensorValue]:
    readings: dict[int, SensorValue] = {}
    first: dict[int, int] = {}
    for index, item in enumerate(items):
        path = f"sensors[{index}]"
        entry = _entry_object(item, path, '{"name":"distance","id":1,"value":1.5}')
        port, value = _reading(entry, path)
        if port in readings:
            raise CodecError(
                f"{path}.id {port} is the port of sensors[{first[port]}] too; "
                "expected one entry per port"
            )
        readings[port] = value
        first[port] = index
    return readings


_A_READING = 'a number like 1.5, text like "straight", true, false or null'
_NOT_TEXT = re.compile("[\x00-\x1f\x7f-\x9f\ud800-\udfff]")


def _reading(entry: dict[str, Any], path: str) -> tuple[int, SensorValue]:
    for key, expected in (("id", "a port number like 1"), ("value", _A_READING)):
        if key not in entry:
            raise CodecError(f"{path}.{key} is missing; expected {expected}")
    port = _port(entry["id"], f"{path}.id", "a port number like 1")
    if port < 0:
        raise CodecError(f"{path}.id {port} is not a port; expected a port number >= 0")
    return port, _sensor_value(entry["value"], f"{path}.value")


def _sensor_value(value: Any, path: str) -> SensorValue:
    if isinstance(value, _OutOfRange):
        raise CodecError(f"{path} {_show(value)} is out of range; expected a finite number")
    if isinstance(value, dict | list):
        raise CodecError(f"{path} is {_kind_of(value)}; expected {_A_READING}")
    if isinstance(value, str):
        bad = _NOT_TEXT.search(value)
        if bad is not None:
            what = "a lone surrogate" if bad.group() >= "\ud800" else "a control character"
            raise CodecError(
                f"{path} {_show(value)} holds {what} (U+{ord(bad.group()):04X}) at character "
                f"{bad.start() + 1}; expected text without control characters"
            )
        return value
    if isinstance(value, bool) or value is None:
        return value
    return float(value)
