"""A session app's error output as the lab server keeps it.

The app writes its error output into a pipe; the server reads it as it comes, whatever the
app writes (a full pipe would stall the app), and writes it to the session's log,
``<data-dir>/logs/<user>/<stamp>-<id>.log``, of a capped size (``SessionLimits.app_log``): a log
that is full is renamed ``….log.1`` (replacing an older one) and a new one begun, so a session
takes at most twice the size and its latest output is always on disk. While the log cannot be
written (a full disk, an I/O error) the server keeps the output's last lines in memory and
tries again now and then; once a write works it writes a line saying how much was lost and
the lines it kept. What is still unwritten when the session ends goes to ``ssh.log``.
The end of the output is kept in memory too, for the server to find why an app ended
(out of memory).
"""

from __future__ import annotations

import asyncio
import contextlib
import os
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

#: the end of an app's error output kept in memory (searched for why an app ended)
TAIL = 256 * 1024
#: how much of the unwritten output is kept while the log cannot be written
KEPT = 64 * 1024
#: seconds between tries at writing a log that could not be written
RETRY_EVERY = 1.0
#: lines of unwritten output put in ``ssh.log`` at a session's end, and their longest shown
REPORTED_LINES = 20
REPORTED_WIDTH = 200


class AppLog:
    """Writes one app's error output to its log of at most ``size`` bytes (0: no cap),
    rotated once; never raises on a write."""

    def __init__(
        self,
        path: Path,
        size: int = 0,
        *,
        opener: Callable[..., Any] = open,
        retry_every: float = RETRY_EVERY,
        clock: Callable[[], float] = time.monotonic,
    ) -> None:
        self.path = Path(path)
        self.size = size
        self._opener = opener
        self._retry_every = retry_every
        self._clock = clock
        self._file: Any = None
        self._written = 0  # bytes in the current file
        #: the end of all output so far (at most TAIL bytes)
        self.tail = bytearray()
        #: output not yet written, while the log cannot be (at most KEPT bytes)
        self._unwritten = bytearray()
        #: lines (and bytes) of output dropped for good while the log could not be written
        self.lost_lines = 0
        self.lost_bytes = 0
        #: why the log cannot be written, None while it can
        self.failure: str | None = None
        self._retry_at = 0.0
        self.rotations = 0
        self.closed = False

    @property
    def rotated(self) -> Path:
        return self.path.with_name(self.path.name + ".1")

    def feed(self, data: bytes) -> None:
        """Take more of the app's output."""
        if not data or self.closed:
            return
        self.tail += data
        del self.tail[:-TAIL]
        if self.failure is not None:
            if self._clock() < self._retry_at:
                self._keep(data)
                return
            self._keep(data)
            self._catch_up()
            return
        self._write(data)

    def close(self) -> None:
        """Write what is left (one last try) and close the file."""
        if self.closed:
            return
        if self.failure is not None:
            self._catch_up()
        self.closed = True
        if self._file is not None:
            with contextlib.suppress(OSError):
                self._file.close()
            self._file = None

    def report(self) -> list[str]:
        """After :meth:`close`: the lines for ``ssh.log`` when output was never written (the
        first says how much and why, the others are the output's last lines), else none."""
        if self.failure is None:
            return []
        text = bytes(self._unwritten).decode("utf-8", "replace")
        lines = [_shown(line) for line in text.splitlines()[-REPORTED_LINES:]]
        kept = self._unwritten.count(b"\n")
        note = (
            f"{self.path} could not be written ({self.failure}): "
            f"{self.lost_lines + kept} lines of the app's error output not written"
        )
        return [note, *lines]

    # -- writing -----------------------------------------------------------------------------
    def _keep(self, data: bytes) -> None:
        self._unwritten += data
        over = len(self._unwritten) - KEPT
        if over > 0:
            cut = self._unwritten.find(b"\n", over)
            cut = over if cut < 0 else cut + 1
            self.lost_lines += self._unwritten.count(b"\n", 0, cut)
            self.lost_bytes += cut
            del self._unwritten[:cut]

    def _catch_up(self) -> None:
        """Try the log again: a note on what was lost, then the kept lines (as many as fit in
        half a log, so the note stays in the same log as they)."""
        kept = bytes(self._unwritten)
        lost_lines, lost_bytes = self.lost_lines, self.lost_bytes
        if self.size and len(kept) > self.size // 2:
            cut = kept.find(b"\n", len(kept) - self.size // 2)
            cut = len(kept) - self.size // 2 if cut < 0 else cut + 1
            lost_lines += kept.count(b"\n", 0, cut)
            lost_bytes += cut
            kept = kept[cut:]
        lines = kept.count(b"\n")
        if lost_lines:
            note = (
                f"[lab server] {lost_lines} lines ({lost_bytes} bytes) of this app's error "
                f"output were lost while its log could not be written ({self.failure}); the "
                f"{lines} lines after them follow\n"
            )
        else:
            note = (
                f"[lab server] this log could not be written for a while ({self.failure}); "
                f"the {lines} lines written meanwhile follow\n"
            )
        self.failure = None
        if self._write(note.encode() + kept, keep=False):
            self._unwritten.clear()
            self.lost_lines = self.lost_bytes = 0
        # else still no room: all stays as it was, for the next try

    def _write(self, data: bytes, keep: bool = True) -> bool:
        view = memoryview(data)
        try:
            if self._file is None:
                self._open()
            if self.size:
                if self._written and self._written + len(view) > self.size:
                    self._rotate()
                view = view[max(0, len(view) - self.size) :]  # more than a log: its end
            while view:
                done = self._file.write(view)
                if done is None:  # a non-blocking file that takes nothing now
                    raise BlockingIOError("the log is busy")
                self._written += done
                view = view[done:]
        except OSError as exc:
            self._failed(exc, bytes(view) if keep else b"")
            return False
        return True

    def _open(self) -> None:
        self.path.parent.mkdir(parents=True, exist_ok=True)
        self._file = self._opener(self.path, "ab", buffering=0)
        self._written = self._file.seek(0, os.SEEK_END)

    def _rotate(self) -> None:
        if self._file is not None:
            with contextlib.suppress(OSError):
                self._file.close()
            self._file = None
        os.replace(self.path, self.rotated)
        self.rotations += 1
        self._open()

    def _failed(self, exc: OSError, data: bytes) -> None:
        self.failure = exc.strerror or str(exc)
        self._retry_at = self._clock() + self._retry_every
        if self._file is not None:
            with contextlib.suppress(OSError):
                self._file.close()
            self._file = None  # opened again at the next try (position, rotation known anew)
        self._keep(data)


def _shown(line: str) -> str:
    """A line of a student's app's output as ``ssh.log`` shows it: printable, not too long."""
    shown = "".join(c if c.isprintable() else "?" for c in line[:REPORTED_WIDTH])
    return shown + ("…" if len(line) > REPORTED_WIDTH else "")


def make_room(folder: Path, quota: int, room: int, keep: set[Path] | frozenset = frozenset()):
    """Remove the oldest files of ``folder`` (a user's logs) until they take at most
    ``quota - room`` bytes, sparing ``keep`` (logs still written); the number removed and
    their bytes. A quota of 0 removes nothing."""
    if quota <= 0:
        return 0, 0
    try:
        entries = [(e.stat().st_mtime, e.stat().st_size, Path(e.path)) for e in os.scandir(folder)
                   if e.is_file(follow_symlinks=False)]  # fmt: skip
    except OSError:
        return 0, 0
    total = sum(size for _, size, _ in entries)
    removed = freed = 0
    for _, size, path in sorted(entries):
        if total <= max(0, quota - room):
            break
        if path in keep:
            continue
        with contextlib.suppress(OSError):
            path.unlink()
            total -= size
            removed += 1
            freed += size
    return removed, freed


class ErrorPipe(asyncio.Protocol):
    """Reads an app's error output from its pipe into an :class:`AppLog`, as it comes."""

    def __init__(self, log: AppLog) -> None:
        self.log = log
        self.done: asyncio.Future[None] = asyncio.get_running_loop().create_future()
        self.transport: asyncio.BaseTransport | None = None

    def connection_made(self, transport: asyncio.BaseTransport) -> None:
        self.transport = transport

    def data_received(self, data: bytes) -> None:
        self.log.feed(data)

    def connection_lost(self, exc: Exception | None) -> None:
        if not self.done.done():
            self.done.set_result(None)

    def close(self) -> None:
        if self.transport is not None:
            self.transport.close()


async def read_errors(log: AppLog, fd: int) -> ErrorPipe:
    """Start reading the pipe's read end ``fd`` (taken over) into ``log``."""
    loop = asyncio.get_running_loop()
    pipe = ErrorPipe(log)
    await loop.connect_read_pipe(lambda: pipe, os.fdopen(fd, "rb", buffering=0))
    return pipe
