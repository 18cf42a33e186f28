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
import socket
import sqlite3
import threading
import time
from abc import ABC, abstractmethod
from collections.abc import Callable, Iterator
from contextlib import AbstractContextManager, contextmanager, suppress
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
#: how long one statement may take in the course database: the server gives up a statement
#: (``statement_timeout``) or a wait for a lock (``lock_timeout``) after this many seconds, and
#: this side gives up a call the server does not answer at all (stopped, or its machine hung
#: while its network still acknowledges) a little later by dropping the connection. Either way
#: the call fails as :class:`StoreUnavailable`: writes are kept pending, nobody waits longer.
ENV_DB_TIMEOUT = "WORKBENCH_DB_TIMEOUT"
DB_TIMEOUT_S = 5.0
DB_TIMEOUT_RANGE = (0.5, 600.0)
#: seconds this side waits beyond the server's own timeout before it drops the connection
CLIENT_GRACE_S = 2.0
MAX_URL = 2048
POSTGRES_SCHEMES = ("postgresql://", "postgres://")


#: the channel every PostgreSQL write transaction notifies (``labs/store/changes.py``)
CHANGES_CHANNEL = "workbench_store"


class StoreError(Exception):
    """The database cannot be opened, read or written; the message names it."""


class StoreDiskError(StoreError):
    """The disk under the database failed (full, over quota, an input/output error): the
    database is not known to be damaged, and a backup must not be put over it."""


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


def db_timeout() -> float:
    """Seconds a course database statement may take: ``$WORKBENCH_DB_TIMEOUT``, else
    :data:`DB_TIMEOUT_S`. A value that is not a number in range is refused, naming it."""
    text = os.environ.get(ENV_DB_TIMEOUT, "").strip()
    if not text:
        return DB_TIMEOUT_S
    low, high = DB_TIMEOUT_RANGE
    try:
        value = float(text)
    except ValueError:
        value = float("nan")
    if not low <= value <= high:
        raise StoreError(
            f"${ENV_DB_TIMEOUT}: {text[:40]!r} is not a number of seconds from {low:g} to "
            f"{high:g} (the default is {DB_TIMEOUT_S:g})"
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
    """A transaction's cursor: ``execute`` takes SQL with ``?`` placeholders. ``deadline``
    (PostgreSQL) is the watch each statement runs under."""

    cursor: Any
    postgres: bool
    deadline: Callable[[], AbstractContextManager[None]] | None = None

    def execute(self, sql: str, params: tuple[Any, ...] | list[Any] = ()) -> Any:
        if self.postgres:
            sql = sql.replace("?", "%s")
        if self.deadline is None:
            self.cursor.execute(sql, tuple(params))
        else:
            with self.deadline():
                self.cursor.execute(sql, tuple(params))
        return self.cursor


class Watchdog:
    """One thread that drops a connection whose statement is still unanswered at its deadline
    (a server that is stopped, or whose machine hangs while its network still acknowledges,
    never fires its own timeout). Shutting the socket makes the waiting call fail at once."""

    def __init__(self, seconds: float):
        self.seconds = seconds
        self._cond = threading.Condition()
        self._due: float | None = None
        self._conn: Any = None
        self._thread: threading.Thread | None = None
        #: the connection last dropped (the call on it failed for that reason)
        self.dropped: Any = None
        self._stopped = False

    @contextmanager
    def watch(self, conn: Any) -> Iterator[None]:
        with self._cond:
            if self._thread is None:
                self._stopped = False
                self._thread = threading.Thread(
                    target=self._run, name="course-db-deadline", daemon=True
                )
                self._thread.start()
            self._due, self._conn = time.monotonic() + self.seconds, conn
            self._cond.notify()
        try:
            yield
        finally:
            with self._cond:
                self._due = self._conn = None

    def stop(self) -> None:
        """End the thread (the backend is closed)."""
        with self._cond:
            self._stopped = True
            self._thread = None
            self._cond.notify()

    def _run(self) -> None:
        with self._cond:
            while not self._stopped:
                if self._due is None:
                    self._cond.wait()
                    continue
                left = self._due - time.monotonic()
                if left > 0:
                    self._cond.wait(left)
                    continue
                self.dropped, conn = self._conn, self._conn
                self._due = self._conn = None
                _shut(conn)


def _shut(conn: Any) -> None:
    try:
        with socket.socket(fileno=os.dup(conn.pgconn.socket)) as sock:
            sock.shutdown(socket.SHUT_RDWR)
    except Exception:  # closed meanwhile: its call is over anyway
        return


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


#: what to do with a database file that is not one (or is damaged): only then a backup helps
NOT_A_DATABASE = "move it aside to start a new one, or restore it from a backup"


def sqlite_failure(where: str | os.PathLike, exc: sqlite3.Error, doing: str) -> StoreError:
    """The error for a failed SQLite call, named for what it is. A full disk and other
    input/output errors say so and what to do, and never advise restoring a backup: the
    database is intact, and an older copy would roll back the sign-off log. Only a file that
    is not a database, or a damaged one, is called unreadable."""
    text = str(exc)
    code = getattr(exc, "sqlite_errorcode", None)
    primary = code & 0xFF if isinstance(code, int) else None
    if primary == sqlite3.SQLITE_FULL or "disk is full" in text:
        return StoreDiskError(
            f"{where}: cannot {doing}: the disk is full (or the account's disk quota is used "
            "up); free some space and try again. The database is not damaged: do not restore "
            "a backup over it"
        )
    if primary == sqlite3.SQLITE_IOERR or "disk I/O error" in text:
        return StoreDiskError(
            f"{where}: cannot {doing}: an input/output error on the disk ({text}); check the "
            "disk and its free space and try again. This is no sign of a damaged database: "
            "do not restore a backup over it"
        )
    if primary in (sqlite3.SQLITE_NOTADB, sqlite3.SQLITE_CORRUPT) or (
        "file is not a database" in text or "malformed" in text
    ):
        return StoreError(f"{where}: not a readable workbench database ({text}); {NOT_A_DATABASE}")
    if primary == sqlite3.SQLITE_CANTOPEN:
        return StoreError(
            f"{where}: cannot open the database file ({text}): check that its folder can be "
            "written (SQLite keeps companion files beside it) and has free space"
        )
    return StoreError(f"{where}: cannot {doing}: {text}")


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
            # the store holds its lock around every use, so threads may share the connection
            # (a screen reads the store in a thread of its own)
            conn = sqlite3.connect(
                path,
                timeout=BUSY_TIMEOUT_MS / 1000,
                isolation_level=None,
                check_same_thread=False,
            )
        except sqlite3.Error as exc:
            raise sqlite_failure(path, exc, "open the database") from None
        backend = cls(path, conn)
        try:
            conn.execute(f"PRAGMA busy_timeout = {BUSY_TIMEOUT_MS}")
            mode = conn.execute("PRAGMA journal_mode = WAL").fetchone()[0]
            if str(mode).lower() != "wal":
                raise StoreError(f"{path}: the database cannot use WAL mode (got {mode})")
            conn.execute("PRAGMA synchronous = FULL")
        except sqlite3.DatabaseError as exc:
            conn.close()
            raise sqlite_failure(path, exc, "open the database") from None
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
            raise sqlite_failure(self.where, exc, "write") from None
        try:
            yield Tx(cur, postgres=False)
        except sqlite3.Error as exc:
            self.conn.rollback()
            raise sqlite_failure(self.where, exc, "write") from None
        except BaseException:
            self.conn.rollback()
            raise
        else:
            try:
                cur.execute("COMMIT")
            except sqlite3.Error as exc:
                self.conn.rollback()
                raise sqlite_failure(self.where, exc, "write") from None

    def read(self, sql: str, params: tuple[Any, ...] = ()) -> list[tuple[Any, ...]]:
        try:
            return self.conn.execute(sql, params).fetchall()
        except sqlite3.DatabaseError as exc:
            raise sqlite_failure(self.where, exc, "read") from None

    def close(self) -> None:
        self.conn.close()


class PostgresBackend(Backend):
    """A PostgreSQL database. The connection is made again after the server went away; while
    it cannot be, every call raises :class:`StoreUnavailable` at once (one new attempt per
    :data:`RETRY_AFTER_S` at most, so a writer never waits on a dead server). Every call has a
    deadline (:func:`db_timeout`): the server's ``statement_timeout`` and ``lock_timeout``, and
    on this side a :class:`Watchdog` that drops the connection of a statement still
    unanswered after them."""

    kind = "postgresql"

    def __init__(self, url: str, *, read_only: bool = False, timeout: float | None = None):
        self.url = url
        self.where = redact(url)
        self.read_only = read_only
        self.timeout = db_timeout() if timeout is None else timeout
        self.conn: Any = None
        self._next_try = 0.0
        self.watchdog = Watchdog(self.timeout + CLIENT_GRACE_S)

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
        given = conninfo_to_dict(self.url)
        try:
            conn = psycopg.connect(
                self.url,
                autocommit=True,
                **{**LINK_DEFAULTS, **given},  # the URL's own settings win
            )
        except psycopg.OperationalError as exc:
            self._next_try = now + RETRY_AFTER_S
            raise StoreUnavailable(
                f"{self.where}: the database cannot be reached: {_first_line(exc)}"
            ) from None
        except psycopg.Error as exc:  # a malformed URL, an unknown option
            raise StoreError(f"{self.where}: cannot connect: {_first_line(exc)}") from None
        try:
            with self.watchdog.watch(conn):
                options = str(given.get("options", ""))
                for name in ("statement_timeout", "lock_timeout"):
                    if name not in options:  # set in the URL (options=-c ...): that wins
                        conn.execute(
                            "SELECT set_config(%s, %s, false)",
                            (name, f"{round(self.timeout * 1000)}ms"),
                        )
                if self.read_only:
                    conn.execute("SET SESSION CHARACTERISTICS AS TRANSACTION READ ONLY")
        except psycopg.Error as exc:
            conn.close()
            self._next_try = now + RETRY_AFTER_S
            raise self._failed(exc, "connect") from None
        self.conn = conn
        return conn

    def _failed(self, exc: Exception, doing: str) -> StoreError:
        """The error to raise for a failed statement: unavailable when the connection was
        lost with it (the server stopped or restarted, or did not answer in time) or the
        server gave it up at its timeout, else a plain one."""
        import psycopg

        conn = self.conn
        seconds = f"{self.timeout:g} s"
        if isinstance(exc, psycopg.errors.QueryCanceled | psycopg.errors.LockNotAvailable):
            self._next_try = time.monotonic() + RETRY_AFTER_S
            return StoreUnavailable(
                f"{self.where}: the database did not answer within {seconds} (busy or locked): "
                f"{_first_line(exc)}"
            )
        if self.watchdog.dropped is not None and self.watchdog.dropped in (conn, None):
            self.watchdog.dropped = None
            self._next_try = time.monotonic() + RETRY_AFTER_S
            return StoreUnavailable(
                f"{self.where}: the database did not answer within {seconds}; the connection "
                "was dropped"
            )
        if conn is None or conn.closed or conn.broken or isinstance(exc, psycopg.InterfaceError):
            self._next_try = time.monotonic() + RETRY_AFTER_S
            return StoreUnavailable(f"{self.where}: the database went away: {_first_line(exc)}")
        return StoreError(f"{self.where}: cannot {doing}: {_first_line(exc)}")

    @contextmanager
    def write(self) -> Iterator[Tx]:
        import psycopg

        conn = self.connection()
        try:
            with conn.cursor() as cur:
                tx = Tx(cur, postgres=True, deadline=lambda: self.watchdog.watch(conn))
                tx.execute("BEGIN")
                try:
                    yield tx
                except BaseException:
                    with suppress(psycopg.Error):
                        tx.execute("ROLLBACK")
                    raise
                # word for the readers that show the store live (labs/store/changes.py): the
                # server sends it at the commit, and never for a write rolled back
                tx.execute(f"NOTIFY {CHANGES_CHANNEL}")
                tx.execute("COMMIT")
        except psycopg.Error as exc:
            raise self._failed(exc, "write") from None

    def read(self, sql: str, params: tuple[Any, ...] = ()) -> list[tuple[Any, ...]]:
        import psycopg

        conn = self.connection()
        try:
            with conn.cursor() as cur:
                tx = Tx(cur, postgres=True, deadline=lambda: self.watchdog.watch(conn))
                return tx.execute(sql, params).fetchall()
        except psycopg.Error as exc:
            raise self._failed(exc, "read") from None

    def close(self) -> None:
        self.watchdog.stop()
        if self.conn is not None:
            self.conn.close()
            self.conn = None


def _first_line(exc: BaseException) -> str:
    text = str(exc).strip()
    return text.splitlines()[0] if text else type(exc).__name__
