"""Run records: one JSON object per line (header, one line per control tick, summary).

The format is documented in ``docs/run-record.md``. Lines are written as the run goes and
flushed regularly, so a crash loses at most the last second of a run.
"""

from __future__ import annotations

import hashlib
import json
import os
import platform
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import IO, Any

import pymunk

import workbench

from .commands import MotorPower, MoveAtPower, Stop, TurnByDegrees, WheelPowers
from .driver import BY_KEYS, NOBODY, Driver

FORMAT = "workbench-run/1"
FLUSH_EVERY = 20


class RecordError(ValueError):
    """A run record that cannot be read, with the line and the reason."""


def versions() -> dict[str, str]:
    return {
        "workbench": workbench.__version__,
        "pymunk": pymunk.version,
        "python": platform.python_version(),
    }


def _r(value: float) -> float:
    return round(value, 4)


def command_json(cmd: object) -> dict[str, Any]:
    """A command in the vocabulary of FSM actions (wheels / motor / move / turn / stop)."""
    if isinstance(cmd, WheelPowers):
        return {"wheels": [_r(cmd.left), _r(cmd.right)]}
    if isinstance(cmd, MotorPower):
        return {"motor": {"wheel": cmd.wheel, "power": _r(cmd.power)}}
    if isinstance(cmd, MoveAtPower):
        return {"move": _r(cmd.power)}
    if isinstance(cmd, TurnByDegrees):
        return {"turn": _r(cmd.degrees)}
    if isinstance(cmd, Stop):
        return {"stop": True}
    raise TypeError(f"{cmd!r} is not a motor command")


class Recorder:
    """Writes a run record to a file (or any text stream)."""

    def __init__(self, target: str | os.PathLike | IO[str]):
        if isinstance(target, str | os.PathLike):
            self.path: Path | None = Path(target)
            self._fh: IO[str] = open(self.path, "w", encoding="utf-8")  # noqa: SIM115
            self._owned = True
        else:
            self.path = None
            self._fh = target
            self._owned = False
        self._pending = 0

    def _write(self, obj: dict[str, Any]) -> None:
        self._fh.write(json.dumps(obj, separators=(",", ":")) + "\n")
        self._pending += 1
        if self._pending >= FLUSH_EVERY:
            self._fh.flush()
            self._pending = 0

    def header(self, **fields: Any) -> None:
        self._write({"type": "header", "format": FORMAT, **fields, "versions": versions()})

    def tick(
        self,
        t: float,
        pose: tuple[float, float, float],
        sensors: dict[int, float | int],
        commands: list[object],
        state: str | None,
        events: list[str],
        variables: dict[str, Any] | None = None,
    ) -> None:
        line: dict[str, Any] = {
            "t": _r(t),
            "pose": [_r(pose[0]), _r(pose[1]), _r(pose[2])],
            "sensors": {str(p): (_r(v) if isinstance(v, float) else v) for p, v in sensors.items()},
        }
        if commands:
            line["cmd"] = [command_json(c) for c in commands]
        if state is not None:
            line["state"] = state
        if variables:
            line["vars"] = {k: (_r(v) if isinstance(v, float) else v) for k, v in variables.items()}
        if events:
            line["events"] = events
        self._write(line)

    def summary(self, metrics: dict[str, Any], **extra: Any) -> None:
        self._write({"type": "summary", **metrics, **extra})

    def close(self) -> None:
        self._fh.flush()
        if self._owned:
            self._fh.close()


@dataclass
class RunRecord:
    header: dict[str, Any]
    ticks: list[dict[str, Any]] = field(default_factory=list)
    summary: dict[str, Any] | None = None


def file_sha256(path: str | os.PathLike) -> str:
    """Hex SHA-256 of a run record file's bytes (raises OSError when it cannot be read)."""
    h = hashlib.sha256()
    with open(path, "rb") as fh:
        for chunk in iter(lambda: fh.read(1 << 16), b""):
            h.update(chunk)
    return h.hexdigest()


def iter_lines(path: str | os.PathLike) -> Iterator[tuple[int, dict[str, Any]]]:
    with open(path, encoding="utf-8") as fh:
        for no, raw in enumerate(fh, start=1):
            if not raw.strip():
                continue
            try:
                obj = json.loads(raw)
            except json.JSONDecodeError as exc:
                raise RecordError(
                    f"{path}:{no}: not JSON ({exc.msg} at column {exc.colno})"
                ) from None
            if not isinstance(obj, dict):
                raise RecordError(f"{path}:{no}: each line must be a JSON object")
            yield no, obj


def read_record(path: str | os.PathLike) -> RunRecord:
    """Load a run record; a record cut short by a crash loads without its summary."""
    record: RunRecord | None = None
    try:
        for no, obj in iter_lines(path):
            kind = obj.get("type")
            if record is None:
                if kind != "header" or obj.get("format") != FORMAT:
                    raise RecordError(
                        f"{path}:{no}: not a workbench run record (the first line must be a "
                        f'header with "format": "{FORMAT}")'
                    )
                record = RunRecord(header=obj)
            elif kind == "summary":
                record.summary = obj
            elif kind is None:
                record.ticks.append(obj)
            else:
                raise RecordError(f"{path}:{no}: unknown line type {kind!r}")
    except OSError as exc:
        raise RecordError(f"{path}: cannot read: {exc.strerror}") from None
    if record is None:
        raise RecordError(f"{path}: empty file, not a run record")
    return record


def recorded_driver(header: dict[str, Any]) -> Driver:
    """Who drove the recorded run.

    A record holds its driver as ``"driven_by": {"kind": ...}``, beside the text older readers
    take: ``"algorithm"`` is an algorithm's name, ``keys`` or ``VIPLE ROLE PEER``, and a record
    served headless says ``"driver": "VIPLE"``. Records written before ``driven_by`` hold only
    that text; this is the one place it is read.
    """
    driver = Driver.from_json(header.get("driven_by"))
    if driver is not None:
        return driver
    if header.get("driver") == "VIPLE":
        return Driver.viple()
    text = header.get("algorithm")
    if not isinstance(text, str) or not text or text == "keys":
        return BY_KEYS
    if text == "nobody":
        return NOBODY
    if text == "VIPLE" or text.startswith("VIPLE "):
        role, _, peer = text.removeprefix("VIPLE").strip().partition(" ")
        return Driver.viple(role, peer)
    return Driver.algorithm(text)
