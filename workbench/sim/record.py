"""Run records: one JSON object per line (header, one line per control tick, summary).

The format is documented in ``docs/run-record.md``. Lines are written as the run goes and
flushed regularly, so a crash loses at most the last second of a run.
"""

from __future__ import annotations

import contextlib
import errno
import hashlib
import json
import math
import os
import platform
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import IO, Any

import pymunk

import workbench
from workbench.files.commits import committed
from workbench.files.terminal import data_problem, terminal_safe

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


def _dumps(obj: object) -> str:
    return json.dumps(obj, separators=(",", ":"))


def _plain_head(
    t: float, pose: tuple[float, float, float], sensors: dict[int, float | int]
) -> list[str] | None:
    """The line's time, pose and sensors put together by hand, as :mod:`json` writes them (a
    float's JSON is its ``repr``, an int's its ``str``), where they are finite floats and ints
    by int ports, as nearly every line's are (a run records 20 lines a simulated second, idle
    or not); None for anything else, which goes through :mod:`json`."""
    x, y, heading = pose
    if not (type(t) is type(x) is type(y) is type(heading) is float):
        return None
    if not math.isfinite(x + y + heading + t):
        return None
    head = [f'{{"t":{_r(t)!r},"pose":[{_r(x)!r},{_r(y)!r},{_r(heading)!r}],"sensors":{{']
    first = True
    for port, value in sensors.items():
        kind = type(value)
        if kind is float:
            value = round(value, 4)
            if value - value != 0.0:  # inf or nan: json spells them its own way
                return None
            text = repr(value)
        elif kind is int:
            text = str(value)
        else:
            return None
        if type(port) is not int:
            return None
        head.append(f'"{port}":{text}' if first else f',"{port}":{text}')
        first = False
    head.append("}")
    return head


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


#: why a record stopped before its run ended (:attr:`Recorder.stopped`)
CAPPED = "cap"
#: it grew faster than :data:`RECORD_RATE` bytes in one simulated second
TOO_FAST = "rate"
DISK_FULL = "disk full"
IO_ERROR = "i/o error"
#: the errors that mean no room is left (the disk, the user's quota, the largest file allowed)
NO_ROOM = (errno.ENOSPC, errno.EDQUOT, errno.EFBIG)
#: room kept under a record's cap for its summary line, written even when the cap was reached
SUMMARY_ROOM = 4096
#: the most bytes a record takes for one simulated second of its run (a run record of an
#: ordinary run takes about 5 kB a second; a program that keeps long texts in its variables
#: can write megabytes)
RECORD_RATE = 500_000


#: the stops after which the summary line is still written
KEEPS_SUMMARY = (CAPPED, TOO_FAST)


@dataclass(frozen=True)
class RecordStop:
    """Why a record stopped taking lines while its run went on."""

    reason: str  # CAPPED, TOO_FAST, DISK_FULL or IO_ERROR
    #: the cap in bytes (CAPPED), the bytes a second (TOO_FAST), or the system's words for
    #: the error
    detail: str = ""
    #: simulated time of the last line kept
    t: float = 0.0


def stop_words(stop: RecordStop) -> str:
    """Why a record stopped, in a few words for a command's report."""
    if stop.reason == CAPPED:
        why = f"it reached its size limit of {int(stop.detail):,} bytes"
    elif stop.reason == TOO_FAST:
        why = f"it grew by more than {int(stop.detail):,} bytes in one simulated second"
    else:
        why = f"it could not be written ({stop.detail})"
    return f"stopped after {stop.t:.1f} s: {why}; the run went on unrecorded"


class Recorder:
    """Writes a run record to a file (or any text stream).

    With a ``cap`` (bytes) the record stops taking tick lines before it grows past it; past
    ``rate`` bytes in one simulated second it stops too; and with ``keep_going`` a write that
    fails (a full disk, an I/O error) stops the record instead of raising: either way
    :attr:`stopped` says why, the run goes on, and the file keeps every whole line written
    before (a record stopped by its cap or rate still gets its summary).
    """

    def __init__(
        self,
        target: str | os.PathLike | IO[str],
        cap: int | None = None,
        keep_going: bool = False,
        rate: int | None = RECORD_RATE,
    ):
        self.cap = cap
        self.rate = rate
        #: the simulated second being counted against :attr:`rate`, and its bytes so far
        self._second = 0
        self._second_size = 0
        self.keep_going = keep_going
        self.stopped: RecordStop | None = None
        #: bytes of whole lines handed to the file so far
        self.size = 0
        #: simulated time of the last line written, and of the last one on disk
        self._t = 0.0
        self._t_kept = 0.0
        self._buffer: list[bytes] = []
        self._lines = 0
        self._file: IO[bytes] | None = None
        self._stream: IO[str] | None = None
        if isinstance(target, str | os.PathLike):
            self.path: Path | None = Path(target)
            self._file = open(self.path, "wb", buffering=0)  # noqa: SIM115
        else:
            self.path = None
            self._stream = target
        #: bytes on disk known to end with a whole line (a failed write is cut back to it)
        self._kept = 0

    def _write(self, obj: dict[str, Any], summary: bool = False, t: float | None = None) -> None:
        if self.stopped is not None and not (summary and self.stopped.reason in KEEPS_SUMMARY):
            return
        self._put((_dumps(obj) + "\n").encode(), summary, t)

    def _put(self, data: bytes, summary: bool = False, t: float | None = None) -> None:
        """One whole line (``data`` ends with its newline) into the record, within its caps."""
        if self.rate is not None and t is not None:
            second = int(t + 1e-9)
            if second != self._second:
                self._second, self._second_size = second, 0
            self._second_size += len(data)
            if self._second_size > self.rate:
                self.stopped = RecordStop(TOO_FAST, str(self.rate), self._t)
                self.flush()
                return
        if self.cap is not None:
            room = self.cap if summary else self.cap - SUMMARY_ROOM
            if self.size + len(data) > room:
                if self.stopped is None:
                    self.stopped = RecordStop(CAPPED, str(self.cap), self._t)
                self.flush()
                return
        self.size += len(data)
        self._buffer.append(data)
        self._lines += 1
        if t is not None:
            self._t = t
        if self._stream is not None:
            self._stream.write(data.decode())  # a stream keeps its own buffer
            self._buffer.clear()
        if summary or self._lines % FLUSH_EVERY == 0:
            self.flush()

    def flush(self) -> None:
        """Hand the lines written so far to the file; a failure stops the record (with
        ``keep_going``) or raises."""
        lines, self._buffer = b"".join(self._buffer), []
        if self.stopped is not None and self.stopped.reason not in KEEPS_SUMMARY:
            return
        try:
            if self._stream is not None:
                self._stream.flush()
            elif self._file is not None:
                view = memoryview(lines)
                while view:
                    written = self._file.write(view)
                    if not written:
                        raise OSError(errno.EIO, "the file took no bytes")
                    view = view[written:]
                self._kept += len(lines)
        except OSError as exc:
            if not self.keep_going:
                raise
            self._failed(exc)
        else:
            self._t_kept = self._t

    def _failed(self, exc: OSError) -> None:
        reason = DISK_FULL if exc.errno in NO_ROOM else IO_ERROR
        self.stopped = RecordStop(reason, exc.strerror or str(exc), self._t_kept)
        if self._file is not None:
            with contextlib.suppress(OSError):  # a half line would make the record unreadable
                os.ftruncate(self._file.fileno(), self._kept)
            with contextlib.suppress(OSError):
                self._file.close()

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
        """One control tick's line (``docs/run-record.md``): the JSON of an object with "t",
        "pose" and "sensors", then "cmd", "state", "vars" and "events" where there are any."""
        if self.stopped is not None:
            return
        head = _plain_head(t, pose, sensors)
        if head is None:
            line = {
                "t": _r(t),
                "pose": [_r(pose[0]), _r(pose[1]), _r(pose[2])],
                "sensors": {
                    str(p): (_r(v) if isinstance(v, float) else v) for p, v in sensors.items()
                },
            }
            head = [_dumps(line)[:-1]]  # (its closing brace comes after the parts below)
        if commands:
            head.append(',"cmd":' + _dumps([command_json(c) for c in commands]))
        if state is not None:
            head.append(',"state":' + _dumps(state))
        if variables:
            plain = {k: (_r(v) if isinstance(v, float) else v) for k, v in variables.items()}
            head.append(',"vars":' + _dumps(plain))
        if events:
            head.append(',"events":' + _dumps(events))
        head.append("}\n")
        self._put("".join(head).encode(), t=t)

    def summary(self, metrics: dict[str, Any], **extra: Any) -> None:
        stop = self.stopped
        if stop is not None and stop.reason == CAPPED:
            extra = {**extra, "record_capped": {"bytes": self.cap, "t": _r(stop.t)}}
        if stop is not None and stop.reason == TOO_FAST:
            extra = {**extra, "record_capped": {"bytes_per_second": self.rate, "t": _r(stop.t)}}
        self._write({"type": "summary", **metrics, **extra}, summary=True)

    def close(self) -> None:
        """Write what is left and close the file; a record closed whole is announced
        (:func:`workbench.files.commits.committed`)."""
        self.flush()
        if self._file is not None and not self._file.closed:
            try:
                self._file.close()
            except OSError as exc:
                if not self.keep_going:
                    raise
                self._failed(exc)
            else:
                if self.path is not None:
                    committed(self.path)


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


#: the lines of a record that hold names and words (the maze's, the driver's): read back, none
#: may hold a control character a terminal would act on (the ticks hold numbers)
_WORDED = ("header", "summary")


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
            if obj.get("type") in _WORDED:
                problem = data_problem(obj)
                if problem:
                    raise RecordError(
                        f"{path}:{no}: {terminal_safe(problem)}; the workbench never writes "
                        "one, so the record was changed after it was written: replay another"
                    )
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
