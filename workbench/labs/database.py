"""The two databases the store can live in: a SQLite file in the data folder (the default,
nothing to set up) or a PostgreSQL database that several lab servers share.

Both are used through :class:`Backend`: one write transaction at a time (:meth:`Backend.write`)
and plain reads (:meth:`Backend.read`). SQL is written once with ``?`` placeholders; the
PostgreSQL backend turns them into psycopg's ``%s``. Errors come out as :class:`StoreError`
naming the database (never its password); a PostgreSQL server that cannot be reached, or that
went away, is :class:`StoreUnavailable`, which the store answers by keeping writes pending.
"""

from __future__ import annotations

import os
import sqlite3
import time
from abc import ABC, abstractmethod
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path
from typing import Any

ENV_DB = "WORKBENCH_DB"
BUSY_TIMEOUT_MS = 10_000
CONNECT_TIMEOUT_S = 3
#: after a failed connection, seconds before the next attempt (writes queue meanwhile)
RETRY_AFTER_S = 1.0
#: how the connection to a course database is made, unless its URL says otherwise: besides the
#: connect timeout, a database host lost without a word (its network gone, the machine off) is
#: noticed within seconds, not after the system's TCP retries (about 15 minutes): a write not
#: acknowledged for 10 s fails, and an idle connection is probed by keepalives
LINK_DEFAULTS: dict[str, Any] = {
    "connect_timeout": CONNECT_TIMEOUT_S,
    "application_name": "viple-workbench",
    "tcp_user_timeout": 10_000,
    "keepalives": 1,
    "keepalives_idle": 30,
    "keepalives_interval": 10,
    "keepalives_count": 3,
}
MAX_URL = 2048
POSTGRES_SCHEMES = ("postgresql://", "postgres://")


class StoreError(Exception):
    """The database cannot be opened, read or written; the message names it."""


class LogMissing(StoreError):
    """There is no sign-off log to read: no database, or no sign-off table in it."""


class StoreUnavailable(StoreError):
    """The PostgreSQL server cannot be reached (down, restarting, or the network is)."""


def resolve_db(option: str | None = None) -> str | None:
    """``--db URL`` if given, else ``$WORKBENCH_DB``; ``None`` means the SQLite file in the
    data folder. Anything but a ``postgresql://`` URL is refused with what to write instead."""
    value = option if option else os.environ.get(ENV_DB, "")
    value = value.strip()
    if not value or value.lower() == "sqlite":
        return None
    where = "--db" if option else f"${ENV_DB}"
    if len(value) > MAX_URL:
        raise StoreError(f"{where}: the database URL is longer than {MAX_URL} characters")
    if not value.lower().startswith(POSTGRES_SCHEMES):
        raise StoreError(
            f"{where}: {redact(value)!r} is not a PostgreSQL URL: write "
            "postgresql://USER[:PASSWORD]@HOST[:PORT]/DBNAME, or leave it out to keep the "
            "store in the data folder (SQLite)"
        )
    return value


def redact(url: str) -> str:
    """A database URL fit for messages and logs: the password replaced by ``***``."""
    scheme, sep, rest = url.partition("://")
    if not sep:
        return url[:80]
    auth, at, host = rest.rpartition("@")
    if not at:
        return url[:200]
    user, colon, _ = auth.partition(":")
    shown = f"{user}:***" if colon else user
    cut = host.split("?", 1)[0]
    return f"{scheme}://{shown}@{cut}"[:200]


@dataclass
class Tx:
    """A transaction's cursor: ``execute`` takes SQL with ``?`` placeholders."""

    cursor: Any
    postgres: bool

    def execute(self, sql: str, params: tuple[Any, ...] | list[Any] = ()) -> Any:
        if self.postgres:
            sql = sql.replace("?", "%s")
        self.cursor.execute(sql, tuple(params))
        return self.cursor


class Backend(ABC):
    """One connection to the store's database."""

    kind = ""
    #: how messages name the database: the file's path or the URL without its password
    where = ""

    @abstractmethod
    def write(self) -> Any:
        """A context manager yielding a :class:`Tx`: one transaction."""

    @abstractmethod
    def read(self, sql: str, params: tuple[Any, ...] = ()) -> list[tuple[Any, ...]]:
        """The rows of one query."""

    @abstractmethod
    def close(self) -> None:
        """Close the connection."""

    @property
    def postgres(self) -> bool:
        return self.kind == "postgresql"


class SqliteBackend(Backend):
    """The SQLite file in WAL mode; each write is one ``BEGIN IMMEDIATE`` transaction, so two
    processes writing at once queue (for up to ten seconds) rather than fail."""

    kind = "sqlite"

    def __init__(self, path: Path, conn: sqlite3.Connection):
        self.path = path
        self.where = str(path)
        self.conn = conn

    @classmethod
    def open(cls, path: Path) -> SqliteBackend:
        try:
            conn = sqlite3.connect(path, timeout=BUSY_TIMEOUT_MS / 1000, isolation_level=None)
        except sqlite3.Error as exc:
            raise StoreError(f"{path}: cannot open the database: {exc}") from None
        backend = cls(path, conn)
        try:
            conn.execute(f"PRAGMA busy_timeout = {BUSY_TIMEOUT_MS}")
            mode = conn.execute("PRAGMA journal_mode = WAL").fetchone()[0]
            if str(mode).lower() != "wal":
                raise StoreError(f"{path}: the database cannot use WAL mode (got {mode})")
            conn.execute("PRAGMA synchronous = FULL")
        except sqlite3.DatabaseError as exc:
            conn.close()
            raise StoreError(
                f"{path}: not a readable workbench database ({exc}); move it aside to start a "
                "new one, or restore it from a backup"
            ) from None
        except StoreError:
            conn.close()
            raise
        return backend

    @contextmanager
    def write(self) -> Iterator[Tx]:
        cur = self.conn.cursor()
        try:
            cur.execute("BEGIN IMMEDIATE")
        except sqlite3.OperationalError as exc:
            raise StoreError(f"{self.where}: cannot write: {exc}") from None
        try:
            yield Tx(cur, postgres=False)
        except sqlite3.Error as exc:
            self.conn.rollback()
            raise StoreError(f"{self.where}: cannot write: {exc}") from None
        except BaseException:
            self.conn.rollback()
            raise
        else:
            try:
                cur.execute("COMMIT")
            except sqlite3.Error as exc:
                self.conn.rollback()
                raise StoreError(f"{self.where}: cannot write: {exc}") from None

    def read(self, sql: str, params: tuple[Any, ...] = ()) -> list[tuple[Any, ...]]:
        try:
            return self.conn.execute(sql, params).fetchall()
        except sqlite3.DatabaseError as exc:
            raise StoreError(f"{self.where}: cannot read: {exc}") from None

    def close(self) -> None:
        self.conn.close()


class PostgresBackend(Backend):
    """A PostgreSQL database. The connection is made again after the server went away; while
    it cannot be, every call raises :class:`StoreUnavailable` at once (one new attempt per
    :data:`RETRY_AFTER_S` at most, so a writer never waits on a dead server)."""

    kind = "postgresql"

    def __init__(self, url: str, *, read_only: bool = False):
        self.url = url
        self.where = redact(url)
        self.read_only = read_only
        self.conn: Any = None
        self._next_try = 0.0

    def connection(self) -> Any:
        import psycopg
        from psycopg.conninfo import conninfo_to_dict

        conn = self.conn
        if conn is not None and not conn.closed and not conn.broken:
            return conn
        if conn is not None:
            conn.close()
            self.conn = None
        now = time.monotonic()
        if now < self._next_try:
            raise StoreUnavailable(f"{self.where}: the database cannot be reached (retrying)")
        try:
            conn = psycopg.connect(
                self.url,
                autocommit=True,
                **{**LINK_DEFAULTS, **conninfo_to_dict(self.url)},  # the URL's own settings win
            )
        except psycopg.OperationalError as exc:
            self._next_try = now + RETRY_AFTER_S
            raise StoreUnavailable(
                f"{self.where}: the database cannot be reached: {_first_line(exc)}"
            ) from None
        except psycopg.Error as exc:  # a malformed URL, an unknown option
            raise StoreError(f"{self.where}: cannot connect: {_first_line(exc)}") from None
        if self.read_only:
            conn.execute("SET SESSION CHARACTERISTICS AS TRANSACTION READ ONLY")
        self.conn = conn
        return conn

    def _failed(self, exc: Exception, doing: str) -> StoreError:
        """The error to raise for a failed statement: unavailable when the connection was
        lost with it (the server stopped or restarted), else a plain one."""
        import psycopg

        conn = self.conn
        if conn is None or conn.closed or conn.broken or isinstance(exc, psycopg.InterfaceError):
            self._next_try = time.monotonic() + RETRY_AFTER_S
            return StoreUnavailable(f"{self.where}: the database went away: {_first_line(exc)}")
        return StoreError(f"{self.where}: cannot {doing}: {_first_line(exc)}")

    @contextmanager
    def write(self) -> Iterator[Tx]:
        import psycopg

        conn = self.connection()
        try:
            with conn.transaction(), conn.cursor() as cur:
                yield Tx(cur, postgres=True)
        except psycopg.Error as exc:
            raise self._failed(exc, "write") from None

    def read(self, sql: str, params: tuple[Any, ...] = ()) -> list[tuple[Any, ...]]:
        import psycopg

        conn = self.connection()
        try:
            with conn.cursor() as cur:
                return Tx(cur, postgres=True).execute(sql, params).fetchall()
        except psycopg.Error as exc:
            raise self._failed(exc, "read") from None

    def close(self) -> None:
        if self.conn is not None:
            self.conn.close()
            self.conn = None


def _first_line(exc: BaseException) -> str:
    text = str(exc).strip()
    return text.splitlines()[0] if text else type(exc).__name__
