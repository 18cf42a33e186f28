"""Word that the store changed, for readers that show it live (the instructor's console, a
student's sign-off status): they read again when another connection committed, not on a clock.

- PostgreSQL: every write transaction ends with ``NOTIFY`` on :data:`CHANNEL` (sent by the
  server at commit, so a rolled-back write says nothing), and a watcher ``LISTEN``s on a
  connection of its own. Word arrives as soon as the server sends it.
- SQLite: a watcher asks ``PRAGMA data_version`` on a read-only connection of its own. The
  number moves whenever any other connection (another process's included) committed a change
  since the last time it asked; asking reads no table, so it costs microseconds and is asked
  every :data:`SQLITE_CHECK` seconds.

A watcher's connection may fail (the server went away): :meth:`Changes.wait` then raises
:class:`~workbench.labs.store.database.StoreUnavailable` and the reader makes a new watcher once
the store answers again. Readers still read now and then without word (a notification lost
with a dropped connection must not hide a request for long): ``EVEN_WITHOUT_WORD`` seconds.
"""

from __future__ import annotations

import contextlib
import math
import sqlite3
import threading
import time
from abc import ABC, abstractmethod
from collections.abc import Callable
from pathlib import Path
from typing import Any

from .database import (
    CHANGES_CHANNEL,
    LINK_DEFAULTS,
    PostgresBackend,
    SqliteBackend,
    StoreUnavailable,
)

#: the PostgreSQL notification channel every write transaction notifies
CHANNEL = CHANGES_CHANNEL
#: how often a SQLite watcher asks the file's data version (seconds)
SQLITE_CHECK = 0.05
#: a reader reads again after this long even with no word of a change (seconds)
EVEN_WITHOUT_WORD = 15.0
#: the least time between two reads at word of a change (seconds): a class saving its
#: progress all the time would otherwise keep a reader reading back to back
MIN_GAP = 0.1


class Changes(ABC):
    """Word of commits to one store by other connections."""

    @abstractmethod
    def wait(self, seconds: float, interrupt: threading.Event) -> bool:
        """Wait up to about ``seconds`` (less when ``interrupt`` is set, for SQLite); True when
        the store changed since the last call."""

    @abstractmethod
    def close(self) -> None:
        """Let the watcher's connection go."""


class SqliteChanges(Changes):
    def __init__(self, path: Path) -> None:
        try:
            self._conn = sqlite3.connect(
                f"{path.resolve().as_uri()}?mode=ro", uri=True, check_same_thread=False
            )
            self._seen = self._version()
        except sqlite3.Error as exc:
            raise StoreUnavailable(f"{path}: cannot watch the database: {exc}") from None
        self.path = path

    def _version(self) -> int:
        return int(self._conn.execute("PRAGMA data_version").fetchone()[0])

    def wait(self, seconds: float, interrupt: threading.Event) -> bool:
        interrupt.wait(min(seconds, SQLITE_CHECK))
        try:
            now = self._version()
        except sqlite3.Error as exc:
            raise StoreUnavailable(f"{self.path}: cannot watch the database: {exc}") from None
        changed, self._seen = now != self._seen, now
        return changed

    def close(self) -> None:
        self._conn.close()


class PostgresChanges(Changes):
    def __init__(self, backend: PostgresBackend) -> None:
        import psycopg
        from psycopg.conninfo import conninfo_to_dict

        self.where = backend.where
        try:
            given = conninfo_to_dict(backend.url)
            self._conn: Any = psycopg.connect(
                backend.url, autocommit=True, **{**LINK_DEFAULTS, **given}
            )
            self._conn.execute(f"LISTEN {CHANNEL}")
        except psycopg.Error as exc:
            raise StoreUnavailable(f"{self.where}: cannot listen for changes: {exc}") from None

    def wait(self, seconds: float, interrupt: threading.Event) -> bool:
        import psycopg

        try:
            return any(True for _ in self._conn.notifies(timeout=seconds, stop_after=1))
        except psycopg.Error as exc:
            raise StoreUnavailable(f"{self.where}: lost the change notifications: {exc}") from None

    def close(self) -> None:
        self._conn.close()


def watch(backend: Any) -> Changes:
    """A watcher of the store ``backend`` is the connection of (a ``Store``'s ``backend``);
    :class:`StoreUnavailable` when it cannot be made now."""
    if isinstance(backend, PostgresBackend):
        return PostgresChanges(backend)
    if isinstance(backend, SqliteBackend):
        return SqliteChanges(backend.path)
    raise TypeError(f"no change watcher for a {type(backend).__name__}")


class ChangeWaiter:
    """What a reading thread waits on between two reads of a store: word of a change, its own
    ``wake`` (a read asked for at once), ``stop``, or :data:`EVEN_WITHOUT_WORD` seconds. While
    the store cannot be watched (it is away), it waits ``away`` seconds at most, so the reader
    tries again at that pace; it makes a new watcher once the store answers."""

    def __init__(
        self,
        watcher: Callable[[], Changes],
        wake: threading.Event,
        stop: threading.Event,
        *,
        check: float = SQLITE_CHECK,
        away: float = 1.0,
        even_without_word: float | None = None,
        min_gap: float = MIN_GAP,
    ) -> None:
        self._make = watcher
        self._wake = wake
        self._stop = stop
        self._check = check
        self._away = away
        self._even_without_word = (
            EVEN_WITHOUT_WORD if even_without_word is None else even_without_word
        )
        self._min_gap = min_gap
        self._last = -math.inf
        self._watcher: Changes | None = None
        self._watch()  # before the first read, so no commit after it goes unseen

    def wait(self) -> None:
        """Return at the first of: a change, ``wake``, ``stop``, the time without word; then
        ``wake`` is cleared. Word of a change waits until ``min_gap`` has passed since the
        last return (``wake`` does not)."""
        wake, stop = self._wake, self._stop
        deadline = time.monotonic() + self._even_without_word
        gap = self._last + self._min_gap - time.monotonic()
        if gap > 0:
            wake.wait(gap)  # word that comes meanwhile is kept by the watcher
        self._wait(wake, stop, deadline)
        wake.clear()
        self._last = time.monotonic()

    def _wait(self, wake: threading.Event, stop: threading.Event, deadline: float) -> None:
        while not stop.is_set() and not wake.is_set():
            left = deadline - time.monotonic()
            if left <= 0:
                break
            watcher = self._watcher
            if watcher is None:
                # a read after the watcher is made misses nothing: read again at once (or, if
                # it cannot be made, after the away pace: the read says whether it is back)
                if not self._watch():
                    wake.wait(min(left, self._away))
                break
            try:
                if watcher.wait(min(left, max(self._check, 0.01)), wake):
                    break
            except StoreUnavailable:
                self.close()
                wake.wait(min(left, self._away))
                break

    def _watch(self) -> bool:
        try:
            self._watcher = self._make()
        except StoreUnavailable:
            return False
        return True

    def close(self) -> None:
        if self._watcher is not None:
            with contextlib.suppress(Exception):
                self._watcher.close()
            self._watcher = None
