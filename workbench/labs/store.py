"""The workbench's own database: sign-off records, exercise progress, drivers, lockouts.

One SQLite file in the data folder, in WAL mode so that the app and a command-line tool can
use it at the same time. Every write is one transaction, committed before the call returns,
so a process killed afterwards loses nothing that was already saved.

The sign-off table holds the log of :mod:`workbench.labs.signlog`: each record's fields, its
signature, its sequence number (unique), the hash of the record before it and its own hash.
Schema 1 had no chain; opening such a database for writing upgrades it to schema 2, giving
its records, in the order they were stored, sequence numbers and hashes as *legacy* entries.
:func:`read_signoffs` reads the table without writing anything (SQLite's read-only mode), for
checking and exporting.
"""

from __future__ import annotations

import json
import math
import os
import sqlite3
import urllib.request
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass, replace
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

import platformdirs

from .signlog import GENESIS, entry_hash, signed_payload

APP_NAME = "viple-workbench"
DB_NAME = "workbench.sqlite3"
ENV_DATA_DIR = "WORKBENCH_DATA"
SCHEMA_VERSION = 2
BUSY_TIMEOUT_MS = 10_000

SCHEMA = """
CREATE TABLE IF NOT EXISTS meta (
    key TEXT PRIMARY KEY,
    value TEXT NOT NULL
);
CREATE TABLE IF NOT EXISTS signoffs (
    id INTEGER PRIMARY KEY AUTOINCREMENT,
    student TEXT NOT NULL,
    partner TEXT NOT NULL,
    driver TEXT NOT NULL,
    lab TEXT NOT NULL,
    exercise TEXT NOT NULL,
    instructor TEXT NOT NULL,
    signed_at TEXT NOT NULL,
    note TEXT NOT NULL,
    override INTEGER NOT NULL,
    run_record TEXT NOT NULL,
    evidence_digest TEXT NOT NULL,
    metrics TEXT NOT NULL,
    signature TEXT NOT NULL,
    seq INTEGER,
    prev_hash TEXT,
    entry_hash TEXT,
    legacy INTEGER NOT NULL DEFAULT 0
);
CREATE INDEX IF NOT EXISTS signoffs_by_student ON signoffs (student, lab, exercise);
CREATE TABLE IF NOT EXISTS progress (
    student TEXT NOT NULL,
    lab TEXT NOT NULL,
    exercise TEXT NOT NULL,
    progress TEXT NOT NULL,
    updated_at TEXT NOT NULL,
    PRIMARY KEY (student, lab, exercise)
);
CREATE TABLE IF NOT EXISTS places (
    student TEXT PRIMARY KEY,
    lab TEXT NOT NULL,
    exercise TEXT NOT NULL,
    updated_at TEXT NOT NULL
);
CREATE TABLE IF NOT EXISTS drivers (
    student TEXT NOT NULL,
    partner TEXT NOT NULL,
    lab TEXT NOT NULL,
    exercise TEXT NOT NULL,
    driver TEXT NOT NULL,
    updated_at TEXT NOT NULL,
    PRIMARY KEY (student, partner, lab, exercise)
);
CREATE TABLE IF NOT EXISTS lockouts (
    instructor TEXT PRIMARY KEY,
    failures INTEGER NOT NULL,
    locked_until REAL NOT NULL,
    updated_at TEXT NOT NULL
);
CREATE TABLE IF NOT EXISTS events (
    id INTEGER PRIMARY KEY AUTOINCREMENT,
    at TEXT NOT NULL,
    instructor TEXT NOT NULL,
    event TEXT NOT NULL,
    detail TEXT NOT NULL
);
"""


# columns added to the sign-off table by schema 2 (the chain)
CHAIN_COLUMNS = (
    ("seq", "INTEGER"),
    ("prev_hash", "TEXT"),
    ("entry_hash", "TEXT"),
    ("legacy", "INTEGER NOT NULL DEFAULT 0"),
)
MAX_SEQ = 2**53  # sequence numbers stay exact wherever the log is kept (JSON, any database)
SEQ_INDEX = "CREATE UNIQUE INDEX IF NOT EXISTS signoffs_by_seq ON signoffs (seq)"


class StoreError(Exception):
    """The database cannot be opened, read or written; the message names the file."""


class LogMissing(StoreError):
    """There is no sign-off log to read: no database, or no sign-off table in it."""


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


def utc_iso(moment: datetime) -> str:
    """A moment as UTC ISO 8601 to the second, e.g. ``2026-02-03T14:05:09Z``."""
    if moment.tzinfo is None:
        raise ValueError("times must carry a time zone")
    return moment.astimezone(UTC).isoformat(timespec="seconds").replace("+00:00", "Z")


def _now() -> datetime:
    return datetime.now(UTC)


@dataclass(frozen=True)
class StoredSignoff:
    """One row of the sign-off table, exactly as stored (it may have been edited since)."""

    id: int
    student: str
    partner: str
    driver: str
    lab: str
    exercise: str
    instructor: str
    signed_at: str
    note: str
    override: bool
    run_record: str
    evidence_digest: str
    metrics: str
    signature: str
    seq: int | None = None
    prev_hash: str = ""
    entry_hash: str = ""
    legacy: bool = False

    def metrics_value(self) -> Any:
        """The metrics as signed (stored as canonical JSON text); text that is not JSON the
        workbench writes (not JSON, NaN, nested too deep) as ``{"unreadable": text}``."""
        try:
            return json.loads(self.metrics, parse_constant=_no_constant, parse_float=_finite)
        except (ValueError, RecursionError):
            return {"unreadable": self.metrics}

    def signed_bytes(self) -> bytes:
        """The bytes the instructor's signature must cover, rebuilt from the columns."""
        evidence = {
            "run_record": self.run_record,
            "digest": self.evidence_digest,
            "metrics": self.metrics_value(),
        }
        chained = not self.legacy
        return signed_payload(
            self.__dict__, evidence, self.seq if chained else None, self.prev_hash
        )

    def label(self) -> str:
        """``#SEQ`` (the place in the log), or the row id when the row has no place."""
        return f"#{self.seq}" if self.seq is not None else f"row id {self.id}"


SIGNOFF_COLUMNS = tuple(StoredSignoff.__dataclass_fields__)
RECORD_COLUMNS = SIGNOFF_COLUMNS[1:14]  # the fields, evidence and signature of a record


@dataclass(frozen=True)
class LockoutState:
    failures: int
    locked_until: float


@dataclass(frozen=True)
class Event:
    at: str
    instructor: str
    event: str
    detail: str


class Store:
    """The database in one data folder. Use :meth:`open`; close it (or use ``with``)."""

    def __init__(self, data_dir: Path, conn: sqlite3.Connection):
        self.data_dir = data_dir
        self.path = data_dir / DB_NAME
        self._conn = conn

    @classmethod
    def open(cls, data_dir: str | os.PathLike | None = None, *, create: bool = True) -> Store:
        """Open (and with ``create``, make if needed) the database in the data folder."""
        folder = resolve_data_dir(data_dir)
        path = folder / DB_NAME
        if not create and not path.is_file():
            raise StoreError(
                f"{path}: no workbench database here (nothing was signed off or saved with "
                "this data folder; see --data-dir)"
            )
        try:
            folder.mkdir(parents=True, exist_ok=True)
        except OSError as exc:
            raise StoreError(f"{folder}: cannot create the data folder: {exc.strerror}") from None
        try:
            conn = sqlite3.connect(path, timeout=BUSY_TIMEOUT_MS / 1000, isolation_level=None)
        except sqlite3.Error as exc:
            raise StoreError(f"{path}: cannot open the database: {exc}") from None
        store = cls(folder, conn)
        try:
            store._prepare()
        except sqlite3.DatabaseError as exc:
            conn.close()
            raise StoreError(
                f"{path}: not a readable workbench database ({exc}); move it aside to start a "
                "new one, or restore it from a backup"
            ) from None
        except StoreError:
            conn.close()
            raise
        return store

    def _prepare(self) -> None:
        conn = self._conn
        conn.execute(f"PRAGMA busy_timeout = {BUSY_TIMEOUT_MS}")
        mode = conn.execute("PRAGMA journal_mode = WAL").fetchone()[0]
        if str(mode).lower() != "wal":
            raise StoreError(f"{self.path}: the database cannot use WAL mode (got {mode})")
        conn.execute("PRAGMA synchronous = FULL")
        with self._write() as cur:
            for statement in SCHEMA.split(";"):
                if statement.strip():
                    cur.execute(statement)
            row = cur.execute("SELECT value FROM meta WHERE key = 'schema_version'").fetchone()
            if row is not None:
                _check_version(self.path, row[0])
            if _chain_missing(cur):
                self._chain_legacy_records(cur)
            cur.execute(SEQ_INDEX)
            cur.execute(
                "INSERT INTO meta (key, value) VALUES ('schema_version', ?) "
                "ON CONFLICT (key) DO UPDATE SET value = excluded.value",
                (str(SCHEMA_VERSION),),
            )

    def _chain_legacy_records(self, cur: sqlite3.Cursor) -> None:
        """Upgrade a schema 1 sign-off table: add the chain's columns and give every record,
        in the order stored, its place in the log as a legacy entry."""
        for name, kind in CHAIN_COLUMNS:
            cur.execute(f"ALTER TABLE signoffs ADD COLUMN {name} {kind}")
        columns = ", ".join(("id", *RECORD_COLUMNS))
        rows = [
            _signoff_from_row(r, ("id", *RECORD_COLUMNS))
            for r in cur.execute(f"SELECT {columns} FROM signoffs ORDER BY id").fetchall()
        ]
        for row in legacy_chain(rows):
            cur.execute(
                "UPDATE signoffs SET seq = ?, prev_hash = ?, entry_hash = ?, legacy = 1 "
                "WHERE id = ?",
                (row.seq, row.prev_hash, row.entry_hash, row.id),
            )

    def close(self) -> None:
        self._conn.close()

    def __enter__(self) -> Store:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    @contextmanager
    def _write(self) -> Iterator[sqlite3.Cursor]:
        """One write transaction; taken at once (IMMEDIATE) so concurrent writers queue."""
        cur = self._conn.cursor()
        try:
            cur.execute("BEGIN IMMEDIATE")
        except sqlite3.OperationalError as exc:
            raise StoreError(f"{self.path}: cannot write: {exc}") from None
        try:
            yield cur
        except BaseException:
            self._conn.rollback()
            raise
        else:
            try:
                cur.execute("COMMIT")
            except sqlite3.Error as exc:
                self._conn.rollback()
                raise StoreError(f"{self.path}: cannot write: {exc}") from None

    def _read(self, sql: str, params: tuple[Any, ...] = ()) -> list[tuple[Any, ...]]:
        try:
            return self._conn.execute(sql, params).fetchall()
        except sqlite3.DatabaseError as exc:
            raise StoreError(f"{self.path}: cannot read: {exc}") from None

    def schema_version(self) -> int:
        rows = self._read("SELECT value FROM meta WHERE key = 'schema_version'")
        return int(rows[0][0])

    # sign-off records

    def append_signoff(self, sign: Callable[[int, str], dict[str, Any]]) -> StoredSignoff:
        """Add a record at the end of the log. ``sign(seq, prev_hash)`` returns the record's
        columns (those of :data:`RECORD_COLUMNS`) signed for that place; it is called inside
        the write transaction, so two processes signing at once queue and never take the same
        place. Returns the row as stored."""
        with self._write() as cur:
            # rows whose seq is not a number were tampered with: verify names them, and the
            # log goes on after the last numbered record
            last = cur.execute(
                "SELECT seq, entry_hash FROM signoffs WHERE typeof(seq) = 'integer' "
                "ORDER BY seq DESC LIMIT 1"
            ).fetchone()
            seq, prev = (int(last[0]) + 1, str(last[1] or "")) if last else (1, GENESIS)
            if seq >= MAX_SEQ:
                raise StoreError(
                    f"{self.path}: the sign-off log claims {seq - 1} records, more than it can "
                    "hold; check it with 'workbench signoff verify'"
                )
            values = sign(seq, prev)
            draft = StoredSignoff(
                id=0,
                **{c: values[c] for c in RECORD_COLUMNS},
                seq=seq,
                prev_hash=prev,
            )
            digest = entry_hash(seq, prev, draft.signed_bytes(), draft.signature)
            columns = (*RECORD_COLUMNS, "seq", "prev_hash", "entry_hash", "legacy")
            row = (
                *(int(values[c]) if c == "override" else values[c] for c in RECORD_COLUMNS),
                seq,
                prev,
                digest,
                0,
            )
            cur.execute(
                f"INSERT INTO signoffs ({', '.join(columns)}) "
                f"VALUES ({', '.join('?' for _ in columns)})",
                row,
            )
            row_id = int(cur.lastrowid or 0)
        return replace(draft, id=row_id, entry_hash=digest)

    def signoffs(self, student: str | None = None, lab: str | None = None) -> list[StoredSignoff]:
        """Records in the order they were signed; ``student`` matches either member of a pair."""
        sql = f"SELECT {', '.join(SIGNOFF_COLUMNS)} FROM signoffs"
        where: list[str] = []
        params: list[Any] = []
        if student:
            where.append("(student = ? OR partner = ?)")
            params += [student, student]
        if lab:
            where.append("lab = ?")
            params.append(lab)
        if where:
            sql += " WHERE " + " AND ".join(where)
        sql += " ORDER BY seq IS NULL, seq, id"
        rows = self._read(sql, tuple(params))
        return [_signoff_from_row(r, SIGNOFF_COLUMNS) for r in rows]

    # exercise progress

    def save_progress(
        self,
        student: str,
        lab: str,
        exercise: str,
        progress: dict[str, Any],
        now: datetime | None = None,
    ) -> None:
        """Replace the saved progress of one student in one exercise (any JSON object)."""
        text = json.dumps(progress, sort_keys=True, allow_nan=False)
        with self._write() as cur:
            cur.execute(
                "INSERT INTO progress (student, lab, exercise, progress, updated_at) "
                "VALUES (?, ?, ?, ?, ?) ON CONFLICT (student, lab, exercise) DO UPDATE SET "
                "progress = excluded.progress, updated_at = excluded.updated_at",
                (student, lab, exercise, text, utc_iso(now or _now())),
            )

    def progress(self, student: str, lab: str | None = None) -> dict[tuple[str, str], dict]:
        """Saved progress by (lab, exercise)."""
        sql = "SELECT lab, exercise, progress FROM progress WHERE student = ?"
        params: tuple[Any, ...] = (student,)
        if lab:
            sql += " AND lab = ?"
            params += (lab,)
        out: dict[tuple[str, str], dict] = {}
        for lab_id, exercise, text in self._read(sql, params):
            try:
                out[(lab_id, exercise)] = json.loads(text)
            except json.JSONDecodeError:
                raise StoreError(
                    f"{self.path}: the saved progress of {student} in {lab_id}/{exercise} is "
                    "not JSON"
                ) from None
        return out

    # where each student was

    def set_place(self, student: str, lab: str, exercise: str, now: datetime | None = None) -> None:
        """Remember the exercise ``student`` has open (the labs reopen there)."""
        with self._write() as cur:
            cur.execute(
                "INSERT INTO places (student, lab, exercise, updated_at) VALUES (?, ?, ?, ?) "
                "ON CONFLICT (student) DO UPDATE SET lab = excluded.lab, "
                "exercise = excluded.exercise, updated_at = excluded.updated_at",
                (student, lab, exercise, utc_iso(now or _now())),
            )

    def place(self, student: str) -> tuple[str, str] | None:
        """The (lab, exercise) ``student`` had open last, if any."""
        rows = self._read("SELECT lab, exercise FROM places WHERE student = ?", (student,))
        return (rows[0][0], rows[0][1]) if rows else None

    # drivers

    def set_driver(
        self,
        student: str,
        partner: str,
        lab: str,
        exercise: str,
        driver: str,
        now: datetime | None = None,
    ) -> None:
        """Record who drove (did the typing in) an exercise for a student or a pair."""
        with self._write() as cur:
            cur.execute(
                "INSERT INTO drivers (student, partner, lab, exercise, driver, updated_at) "
                "VALUES (?, ?, ?, ?, ?, ?) ON CONFLICT (student, partner, lab, exercise) "
                "DO UPDATE SET driver = excluded.driver, updated_at = excluded.updated_at",
                (student, partner, lab, exercise, driver, utc_iso(now or _now())),
            )

    def drivers(self, student: str, partner: str = "") -> dict[tuple[str, str], str]:
        rows = self._read(
            "SELECT lab, exercise, driver FROM drivers WHERE student = ? AND partner = ?",
            (student, partner),
        )
        return {(lab, exercise): driver for lab, exercise, driver in rows}

    # passphrase lockout

    def lockout(self, instructor: str) -> LockoutState:
        rows = self._read(
            "SELECT failures, locked_until FROM lockouts WHERE instructor = ?", (instructor,)
        )
        if not rows:
            return LockoutState(0, 0.0)
        return LockoutState(int(rows[0][0]), float(rows[0][1]))

    def record_failure(
        self, instructor: str, now: datetime, limit: int, lock_seconds: float
    ) -> LockoutState:
        """Count a wrong passphrase; the ``limit``-th in a row locks until now + lock_seconds."""
        with self._write() as cur:
            row = cur.execute(
                "SELECT failures FROM lockouts WHERE instructor = ?", (instructor,)
            ).fetchone()
            failures = (int(row[0]) if row else 0) + 1
            locked_until = 0.0
            if failures >= limit:
                locked_until = now.timestamp() + lock_seconds
                failures = 0
            cur.execute(
                "INSERT INTO lockouts (instructor, failures, locked_until, updated_at) "
                "VALUES (?, ?, ?, ?) ON CONFLICT (instructor) DO UPDATE SET "
                "failures = excluded.failures, locked_until = excluded.locked_until, "
                "updated_at = excluded.updated_at",
                (instructor, failures, locked_until, utc_iso(now)),
            )
        return LockoutState(failures, locked_until)

    def clear_failures(self, instructor: str, now: datetime) -> None:
        with self._write() as cur:
            cur.execute(
                "UPDATE lockouts SET failures = 0, locked_until = 0, updated_at = ? "
                "WHERE instructor = ?",
                (utc_iso(now), instructor),
            )

    def log_event(self, instructor: str, event: str, detail: str, now: datetime) -> None:
        with self._write() as cur:
            cur.execute(
                "INSERT INTO events (at, instructor, event, detail) VALUES (?, ?, ?, ?)",
                (utc_iso(now), instructor, event, detail),
            )

    def events(self, instructor: str | None = None) -> list[Event]:
        sql = "SELECT at, instructor, event, detail FROM events"
        params: tuple[Any, ...] = ()
        if instructor:
            sql += " WHERE instructor = ?"
            params = (instructor,)
        return [Event(*r) for r in self._read(sql + " ORDER BY id", params)]


def _no_constant(name: str) -> Any:
    raise ValueError(f"{name} is not a JSON number")


def _finite(text: str) -> float:
    value = float(text)
    if not math.isfinite(value):
        raise ValueError(f"{text} is too large")
    return value


def _signoff_from_row(row: tuple[Any, ...], names: tuple[str, ...]) -> StoredSignoff:
    data = dict(zip(names, row, strict=True))
    for name in names:
        value = data[name]
        if name in ("override", "legacy"):
            data[name] = bool(value)
        elif name == "seq":
            data[name] = value if isinstance(value, int) else None
        elif name != "id":
            data[name] = "" if value is None else str(value)
    return StoredSignoff(**data)


def legacy_chain(rows: list[StoredSignoff]) -> list[StoredSignoff]:
    """Schema 1 records (in the order stored) as the legacy entries that start the log."""
    out: list[StoredSignoff] = []
    prev = GENESIS
    for seq, row in enumerate(rows, 1):
        entry = replace(row, seq=seq, prev_hash=prev, legacy=True)
        prev = entry_hash(seq, prev, entry.signed_bytes(), entry.signature)
        out.append(replace(entry, entry_hash=prev))
    return out


def _check_version(path: Path, value: object) -> int:
    if not str(value).isdigit():
        raise StoreError(f"{path}: the schema version {value!r} is not a number")
    if int(str(value)) > SCHEMA_VERSION:
        raise StoreError(
            f"{path}: written by a newer workbench (schema {value}, this one knows "
            f"{SCHEMA_VERSION}); update the workbench"
        )
    return int(str(value))


def _columns(conn: sqlite3.Connection | sqlite3.Cursor, table: str) -> set[str]:
    return {r[1] for r in conn.execute(f"PRAGMA table_info({table})").fetchall()}


def _chain_missing(cur: sqlite3.Cursor) -> bool:
    return "seq" not in _columns(cur, "signoffs")


def read_signoffs(data_dir: str | os.PathLike) -> list[StoredSignoff]:
    """The sign-off log of the database in ``data_dir``, in the order of the log, read in
    SQLite's read-only mode: nothing is created, upgraded or written. A schema 1 table is
    read as the legacy entries an upgrade would make. Raises :class:`LogMissing` when there
    is no database or no sign-off table, :class:`StoreError` when the file cannot be read."""
    path = Path(data_dir) / DB_NAME
    if not path.is_file():
        raise LogMissing(
            f"{path}: no workbench database here (nothing was signed off with this data "
            "folder, or the file was deleted; see --data-dir)"
        )
    uri = "file:" + urllib.request.pathname2url(str(path.resolve())) + "?mode=ro"
    try:
        conn = sqlite3.connect(uri, uri=True, timeout=BUSY_TIMEOUT_MS / 1000)
    except sqlite3.Error as exc:
        raise StoreError(f"{path}: cannot open the database: {exc}") from None
    try:
        tables = {r[0] for r in conn.execute("SELECT name FROM sqlite_master WHERE type = 'table'")}
        if "meta" not in tables:
            raise StoreError(f"{path}: not a workbench database (it has no meta table)")
        version = conn.execute("SELECT value FROM meta WHERE key = 'schema_version'").fetchone()
        if version is None:
            raise StoreError(f"{path}: not a workbench database (no schema version)")
        _check_version(path, version[0])
        if "signoffs" not in tables:
            raise LogMissing(
                f"{path}: the sign-off table is missing: the log was deleted from the database"
            )
        if "seq" in _columns(conn, "signoffs"):
            sql = f"SELECT {', '.join(SIGNOFF_COLUMNS)} FROM signoffs"
            rows = conn.execute(sql + " ORDER BY seq IS NULL, seq, id").fetchall()
            return [_signoff_from_row(r, SIGNOFF_COLUMNS) for r in rows]
        names = ("id", *RECORD_COLUMNS)
        rows = conn.execute(f"SELECT {', '.join(names)} FROM signoffs ORDER BY id").fetchall()
        return legacy_chain([_signoff_from_row(r, names) for r in rows])
    except sqlite3.DatabaseError as exc:
        raise StoreError(
            f"{path}: not a readable workbench database ({exc}); restore it from a backup"
        ) from None
    finally:
        conn.close()
