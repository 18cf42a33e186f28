"""The workbench's own database: sign-off records, exercise progress, drivers, lockouts, and
(in PostgreSQL) the instructors' roster.

By default one SQLite file in the data folder, in WAL mode so that the app and a command-line
tool can use it at the same time; given a ``postgresql://`` URL (``--db`` or
``$WORKBENCH_DB``), one PostgreSQL database that every lab server of a course shares. Every
write is one transaction, committed before the call returns, so a process killed afterwards
loses nothing that was already saved. The schema is built by the numbered steps of
:mod:`workbench.labs.store.migrations`.

The sign-off table holds the log of :mod:`workbench.labs.signlog`: each record's fields, its
signature, its sequence number (unique), the hash of the record before it and its own hash.
Schema 1 had no chain; opening such a database for writing upgrades it to schema 2, giving
its records, in the order they were stored, sequence numbers and hashes as *legacy* entries.
:func:`read_signoffs` reads the table without writing anything (SQLite's read-only mode), for
checking and exporting.
"""

from __future__ import annotations

import contextlib
import logging
import os
import sqlite3
import threading
import urllib.request
from collections.abc import Callable, Iterator
from concurrent.futures import Future, ThreadPoolExecutor
from contextlib import contextmanager
from dataclasses import replace
from pathlib import Path
from typing import Any

import platformdirs

from workbench.files.private import PRIVATE_FILE, private_dir, tighten

from ..signlog import GENESIS, entry_hash
from .changes import Changes, watch
from .database import (
    BUSY_TIMEOUT_MS,
    Backend,
    LogMissing,
    PostgresBackend,
    SqliteBackend,
    StoreDiskError,
    StoreError,
    StoreUnavailable,
    Tx,
    resolve_db,
    sqlite_failure,
)
from .instructor_rows import InstructorRows
from .migrations import RECORD_COLUMNS, check_version, latest, migrate
from .pending import FIELDS, PendingWrite, load_pending, save_pending
from .progress_rows import ProgressRows
from .queue import QueueRows
from .rows import utc_iso
from .signoff_rows import (
    SIGNOFF_COLUMNS,
    Event,
    LockoutState,
    SignoffRows,
    StoredSignoff,
    signoff_from_row,
)
from .workspace_rows import WorkspaceRows

__all__ = [
    "SIGNOFF_COLUMNS",
    "Event",
    "LockoutState",
    "LogMissing",
    "Store",
    "StoreDiskError",
    "StoreError",
    "StoreUnavailable",
    "StoredSignoff",
    "read_signoffs",
    "resolve_data_dir",
    "resolve_db",
    "utc_iso",
]

log = logging.getLogger(__name__)

APP_NAME = "viple-workbench"
DB_NAME = "workbench.sqlite3"
ENV_DATA_DIR = "WORKBENCH_DATA"
SCHEMA_VERSION = latest("sqlite")
#: the table of each kind of write that may be kept pending (its columns: pending.FIELDS)
TABLES = {"progress": "progress", "place": "places", "driver": "drivers"}


def upsert(kind: str, only_newer: bool = False) -> str:
    """The statement that saves one write of ``kind`` (see :mod:`.pending`). ``only_newer``
    leaves a row alone that was saved later than the write (a write kept in a file by an
    earlier app must not undo what the student saved since, on this server or another)."""
    table, fields = TABLES[kind], FIELDS[kind]
    key = {"progress": "student, lab, exercise", "place": "student",
           "driver": "student, partner, lab, exercise"}[kind]  # fmt: skip
    changed = [f for f in fields if f not in key.split(", ")]
    sql = (
        f"INSERT INTO {table} ({', '.join(fields)}) VALUES ({', '.join('?' for _ in fields)}) "
        f"ON CONFLICT ({key}) DO UPDATE SET " + ", ".join(f"{f} = excluded.{f}" for f in changed)
    )
    if only_newer:
        sql += f" WHERE {table}.updated_at <= excluded.updated_at"
    return sql


def default_data_dir() -> Path:
    """The per-user data folder (e.g. ~/.local/share/viple-workbench on Linux)."""
    return Path(platformdirs.user_data_dir(APP_NAME, appauthor=False))


def resolve_data_dir(option: str | os.PathLike | None = None) -> Path:
    """``--data-dir`` if given, else ``$WORKBENCH_DATA``, else the per-user data folder."""
    if option:
        return Path(option).expanduser()
    env = os.environ.get(ENV_DATA_DIR)
    if env:
        return Path(env).expanduser()
    return default_data_dir()


class Store:
    """The store of one data folder (SQLite) or of a whole course (PostgreSQL, ``db``). Use
    :meth:`open`; close it (or use ``with``).

    The store is the one connection, and what waits for it; what is kept is reached through
    its repositories, each over the same connection: :attr:`progress` (progress, places,
    drivers), :attr:`signoffs` (the log, lockouts, events), :attr:`queue` (the sign-off
    queue), :attr:`workspaces` (the students' files) and, in a course database only,
    :attr:`instructors` (the roster and sealed keys; ``None`` in SQLite, whose data folder
    keeps them in files: :func:`workbench.labs.signoff.roster.roster_keys`).

    Saving progress, places and drivers never fails because a PostgreSQL server is down: the
    write is kept pending (the newest per exercise) and written by :meth:`flush`; their return
    value says whether it reached the database. While the database is away (the last write
    could not reach it) a new write does not try it again: a front end calls :meth:`flush`
    now and then, in a thread of its own (each call may wait for the connection's timeout),
    and the store is safe to use from two threads. With :meth:`keep_pending_in` what is
    pending is also kept in a file, so that a later app writes it. Sign-offs and the lockout
    need the database and raise :class:`StoreUnavailable` while it is away."""

    def __init__(self, data_dir: Path, backend: Backend):
        self.data_dir = data_dir
        self.backend = backend
        #: the SQLite file (``None`` for PostgreSQL)
        self.path: Path | None = backend.path if isinstance(backend, SqliteBackend) else None
        self.where = backend.where
        #: what waits for the database, by key; True for a write kept from an earlier app
        self._pending: dict[tuple[str, ...], tuple[PendingWrite, bool]] = {}
        self._migrated = False
        #: the database did not answer the last write: new ones wait for :meth:`flush`
        self.offline = False
        #: guards what is pending (held briefly), and the connection (held while it is used)
        self._lock = threading.RLock()
        self._io = threading.RLock()
        self._pending_file: Path | None = None
        self._pending_student = ""
        #: why the pending writes could not be kept in their file ("" when they could)
        self.pending_file_problem = ""
        #: with :meth:`write_in_background`: the one thread that writes, and the flush it has
        #: waiting (not started yet), which a new write joins
        self._writer: ThreadPoolExecutor | None = None
        self._queued: Future[bool] | None = None
        self._on_trouble: Callable[[StoreError], None] | None = None
        #: what opening the store changed (a data folder open to others made private)
        self.notices: list[str] = []
        self.progress = ProgressRows(self)
        self.signoffs = SignoffRows(self)
        self.queue = QueueRows(self)
        self.workspaces = WorkspaceRows(self)
        self.instructors = InstructorRows(self) if backend.postgres else None

    @classmethod
    def open(
        cls,
        data_dir: str | os.PathLike | None = None,
        *,
        create: bool = True,
        db: str | None = None,
        offline_ok: bool = False,
    ) -> Store:
        """Open the store: the PostgreSQL database ``db`` (a URL; see :func:`resolve_db`) or
        else the SQLite file in the data folder (with ``create``, made if needed). Missing
        schema steps are applied. With ``offline_ok`` a PostgreSQL server that cannot be
        reached gives a store that keeps writes pending until it can (:attr:`available`)."""
        folder = resolve_data_dir(data_dir)
        if db:
            store = cls(folder, PostgresBackend(db))
            try:
                store._ensure_schema()
            except StoreUnavailable:
                if not offline_ok:
                    store.close()
                    raise
            except StoreError:
                store.close()
                raise
            return store
        path = folder / DB_NAME
        if not create and not path.is_file():
            raise StoreError(
                f"{path}: no workbench database here (nothing was signed off or saved with "
                "this data folder; see --data-dir)"
            )
        notices: list[str] = []
        try:
            notices.append(private_dir(folder))
            if not path.exists():
                _create_database(path)
            refuse_empty(path)
            for name in (DB_NAME, f"{DB_NAME}-wal", f"{DB_NAME}-shm"):
                notices.append(tighten(folder / name))
        except OSError as exc:
            raise StoreError(f"{exc.filename or folder}: cannot set up the data folder: "
                             f"{exc.strerror}") from None  # fmt: skip
        store = cls(folder, SqliteBackend.open(path))
        try:
            store._ensure_schema()
        except StoreError:
            store.close()
            raise
        store.notices = [n for n in notices if n]
        for notice in store.notices:
            log.warning("%s", notice)
        return store

    def _ensure_schema(self) -> None:
        if not self._migrated:
            migrate(self.backend)
            self._migrated = True

    @property
    def postgres(self) -> bool:
        return self.backend.postgres

    def watch_changes(self) -> Changes:
        """A watcher of commits to this store by other connections (``changes.py``), with a
        connection of its own: for one reading thread. :class:`StoreUnavailable` when it cannot
        be made now."""
        return watch(self.backend)

    @property
    def available(self) -> bool:
        """Whether the database answered the last time it was asked (and nothing is pending)."""
        return self._migrated and not self._pending

    @property
    def pending(self) -> int:
        """Writes kept until the database can be reached again."""
        return len(self._pending)

    def close(self) -> None:
        """Close the connection; writing in the background, without waiting for a write on
        its way (the writing thread closes it once that write is done or given up)."""
        writer = self._writer
        if writer is None:
            with self._io:
                self.backend.close()
            return
        with self._lock:
            if self._queued is not None:
                self._queued.cancel()
                self._queued = None
            writer.submit(self._close_backend)
            writer.shutdown(wait=False)

    def _close_backend(self) -> None:
        with self._io:
            self.backend.close()

    def write_in_background(self, on_trouble: Callable[[StoreError], None]) -> None:
        """From now on a save never waits for the database: it is kept pending and written
        by a thread of the store's own, one flush at a time (:meth:`flush_soon`). When a
        write in that thread fails, ``on_trouble`` is called there with the error: a
        :class:`StoreUnavailable` when the database is away or did not answer in time (the
        write stays pending), another :class:`StoreError` when it was refused."""
        with self._lock:
            self._on_trouble = on_trouble
            if self._writer is None:
                self._writer = ThreadPoolExecutor(1, thread_name_prefix="store-writer")

    @property
    def in_background(self) -> bool:
        return self._writer is not None

    def flush_soon(self) -> Future[bool]:
        """A :meth:`flush` in the store's writing thread (see :meth:`write_in_background`);
        a flush already waiting there is shared. Its result is that of :meth:`flush`."""
        with self._lock:
            if self._writer is None:
                raise RuntimeError("the store does not write in the background")
            if self._queued is None:
                self._queued = self._writer.submit(self._flush_in_writer)
            return self._queued

    def _flush_in_writer(self) -> bool:
        with self._lock:
            self._queued = None  # writes kept from now on go with the next flush
        try:
            done = self.flush()
        except StoreError as exc:
            self._tell(exc)
            raise
        if not done:
            self._tell(StoreUnavailable(f"{self.where}: the database cannot be reached"))
        return done

    def _tell(self, exc: StoreError) -> None:
        if self._on_trouble is not None:
            try:
                self._on_trouble(exc)
            except Exception:  # whoever listens is gone (the app ending): the writes are kept
                return

    def __enter__(self) -> Store:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    @contextmanager
    def write(self) -> Iterator[Tx]:
        """One write transaction; on SQLite taken at once (IMMEDIATE) so writers queue."""
        with self._io:
            self._ensure_schema()
            with self.backend.write() as tx:
                yield tx

    def read(self, sql: str, params: tuple[Any, ...] = ()) -> list[tuple[Any, ...]]:
        with self._io:
            self._ensure_schema()
            return self.backend.read(sql, params)

    def waiting(self) -> list[PendingWrite]:
        """The writes kept until the database can be reached again, oldest first."""
        with self._lock:
            return [w for w, _ in self._pending.values()]

    def keep(self, write: PendingWrite) -> bool:
        """Write one upsert, or keep it pending while the database is away; the newest write
        of a key replaces an older pending one. True when it (and all pending) was written,
        or, writing in the background, when it is on its way (the database was answering)."""
        with self._lock:
            self._pending.pop(write.key, None)
            self._pending[write.key] = (write, False)
            if self.offline:
                self._persist()
                return False  # no new try here: flush() does it, off the caller's thread
            if self._writer is not None:
                self.flush_soon()
                return True
        return self.flush()

    def flush(self) -> bool:
        """Write everything pending in one transaction. True when nothing is left pending;
        False while the database cannot be reached. Other errors drop what was pending (it
        would fail again) and are raised."""
        with self._lock:
            if not self._pending:
                self.offline = False
                return True
            batch = dict(self._pending)
        try:
            with self.write() as tx:
                for write, earlier in batch.values():
                    tx.execute(upsert(write.kind, only_newer=earlier), write.values)
        except StoreUnavailable:
            with self._lock:
                self.offline = True
                self._persist()
            return False
        except StoreError:
            with self._lock:
                for key in batch:
                    self._pending.pop(key, None)
                self._persist()
            raise
        with self._lock:
            self.offline = False
            for key, value in batch.items():
                if self._pending.get(key) == value:
                    del self._pending[key]
            self._persist()
            return not self._pending

    def keep_pending_now(self) -> None:
        """Write what is pending to its file now (an app ending while a write may still be
        on its way keeps it for the next app)."""
        with self._lock:
            self._persist()

    def keep_pending_in(self, path: Path, student: str) -> list[str]:
        """Keep ``student``'s pending writes in the file ``path`` from now on, and take up the
        writes an earlier app kept there (they are saved by the next :meth:`flush`, each only
        where the database holds nothing newer). Returns what was left out of the file."""
        writes, problems = load_pending(path, student)
        with self._lock:
            self._pending_file = path
            self._pending_student = student
            for write in writes:
                self._pending.setdefault(write.key, (write, True))
        return problems

    def _persist(self) -> None:
        path = self._pending_file
        if path is None:
            return
        student = self._pending_student
        mine = [w for w, _ in self._pending.values() if w.values[0] == student]
        try:
            save_pending(path, student, mine)
            self.pending_file_problem = ""
        except OSError as exc:
            self.pending_file_problem = f"cannot keep the pending writes in {path}: {exc}"

    def schema_version(self) -> int:
        rows = self.read("SELECT value FROM meta WHERE key = 'schema_version'")
        return int(rows[0][0])

    def migrations(self) -> list[tuple[int, str]]:
        """The schema steps applied to this store: (version, name)."""
        rows = self.read("SELECT version, name FROM schema_migrations ORDER BY version")
        return [(int(v), str(n)) for v, n in rows]


def _create_database(path: Path) -> None:
    """Make a new, empty workbench database at ``path``, private to the account: built under
    another name and then linked into place, so that no other process ever finds an empty file
    there (an empty file at ``path`` is refused: see :func:`refuse_empty`). When another
    process made one first, theirs is kept."""
    part = path.with_name(f".{path.name}.{os.getpid()}.{threading.get_ident()}.new")
    try:
        os.close(os.open(part, os.O_WRONLY | os.O_CREAT | os.O_TRUNC, PRIVATE_FILE))
        os.chmod(part, PRIVATE_FILE)
        backend = SqliteBackend.open(part)
        try:
            migrate(backend)
        finally:
            backend.close()
        try:
            os.link(part, path)
        except FileExistsError:
            pass  # made by another process meanwhile
        except OSError:  # a file system without hard links
            if not path.exists():
                os.replace(part, path)
    finally:
        for leftover in (part, Path(f"{part}-wal"), Path(f"{part}-shm")):
            with contextlib.suppress(FileNotFoundError):
                leftover.unlink()


def refuse_empty(path: Path) -> None:
    """Refuse a database file of 0 bytes: it is not a workbench database (the workbench never
    leaves one), and opening it would silently start a new, empty store in its place."""
    try:
        size = path.stat().st_size
    except FileNotFoundError:
        return
    if size == 0 and path.is_file():
        raise StoreError(
            f"{path}: an empty file (0 bytes), not a workbench database; if the store was "
            f"lost, restore it from a backup, or move the file aside to start a new one"
        )


def legacy_chain(rows: list[StoredSignoff]) -> list[StoredSignoff]:
    """Schema 1 records (in the order stored) as the legacy entries that start the log."""
    out: list[StoredSignoff] = []
    prev = GENESIS
    for seq, row in enumerate(rows, 1):
        entry = replace(row, seq=seq, prev_hash=prev, legacy=True)
        prev = entry_hash(seq, prev, entry.signed_bytes(), entry.signature)
        out.append(replace(entry, entry_hash=prev))
    return out


def read_signoffs(data_dir: str | os.PathLike, db: str | None = None) -> list[StoredSignoff]:
    """The sign-off log, in the order of the log, read without writing anything: from the
    PostgreSQL database ``db`` (in a read-only session) or else from the SQLite file in
    ``data_dir`` (in SQLite's read-only mode). Nothing is created or upgraded; a schema 1
    table is read as the legacy entries an upgrade would make. Raises :class:`LogMissing`
    when there is no database or no sign-off table, :class:`StoreError` when it cannot be
    read."""
    if db:
        backend = PostgresBackend(db, read_only=True)
        try:
            return _read_log(backend.read, "postgresql", backend.where)
        finally:
            backend.close()
    path = Path(data_dir) / DB_NAME
    if not path.is_file():
        raise LogMissing(
            f"{path}: no workbench database here (nothing was signed off with this data "
            "folder, or the file was deleted; see --data-dir)"
        )
    refuse_empty(path)
    uri = "file:" + urllib.request.pathname2url(str(path.resolve())) + "?mode=ro"
    try:
        conn = sqlite3.connect(uri, uri=True, timeout=BUSY_TIMEOUT_MS / 1000)
    except sqlite3.Error as exc:
        raise sqlite_failure(path, exc, "open the database") from None

    def read(sql: str, params: tuple[Any, ...] = ()) -> list[tuple[Any, ...]]:
        return conn.execute(sql, params).fetchall()

    try:
        return _read_log(read, "sqlite", str(path))
    except sqlite3.DatabaseError as exc:
        raise sqlite_failure(path, exc, "read the sign-off log") from None
    finally:
        conn.close()


def _read_log(
    read: Callable[..., list[tuple[Any, ...]]], kind: str, where: str
) -> list[StoredSignoff]:
    if kind == "sqlite":
        tables = {r[0] for r in read("SELECT name FROM sqlite_master WHERE type = 'table'")}
    else:
        tables = {
            r[0]
            for r in read(
                "SELECT table_name FROM information_schema.tables "
                "WHERE table_schema = current_schema()"
            )
        }
    if "meta" not in tables:
        raise (LogMissing if not tables else StoreError)(
            f"{where}: not a workbench database (it has no meta table)"
        )
    version = read("SELECT value FROM meta WHERE key = 'schema_version'")
    if not version:
        raise StoreError(f"{where}: not a workbench database (no schema version)")
    check_version(where, version[0][0], kind)
    if "signoffs" not in tables:
        raise LogMissing(
            f"{where}: the sign-off table is missing: the log was deleted from the database"
        )
    if kind == "sqlite":
        columns = {r[1] for r in read("PRAGMA table_info(signoffs)")}
    else:
        columns = {
            r[0]
            for r in read(
                "SELECT column_name FROM information_schema.columns "
                "WHERE table_schema = current_schema() AND table_name = 'signoffs'"
            )
        }
    if "seq" in columns:
        sql = f"SELECT {', '.join(SIGNOFF_COLUMNS)} FROM signoffs"
        rows = read(sql + " ORDER BY seq IS NULL, seq, id")
        return [signoff_from_row(r, SIGNOFF_COLUMNS) for r in rows]
    names = ("id", *RECORD_COLUMNS)
    rows = read(f"SELECT {', '.join(names)} FROM signoffs ORDER BY id")
    return legacy_chain([signoff_from_row(r, names) for r in rows])
