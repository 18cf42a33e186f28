"""The sign-off log in the store, and what guards it: each record with its place in the
hash-chained log (:mod:`.signlog`), the lockout that counts an instructor's wrong
passphrases, and the events signing leaves behind."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, replace
from datetime import UTC, datetime
from typing import Any

from ..signlog import entry_hash, next_place, parse_metrics, signed_payload
from . import workspace_rows
from .database import StoreError
from .migrations import RECORD_COLUMNS, SIGNOFF_LOCK
from .rows import Rows, utc_iso

MAX_SEQ = 2**53  # sequence numbers stay exact wherever the log is kept (JSON, any database)


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
        return parse_metrics(self.metrics)

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
assert SIGNOFF_COLUMNS[1:14] == RECORD_COLUMNS  # the fields, evidence and signature of a record


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


class SignoffRows:
    """The sign-off records, lockouts and events, over the store's connection."""

    def __init__(self, rows: Rows) -> None:
        self.rows = rows

    def append(
        self, sign: Callable[[int, str], dict[str, Any]], evidence: bytes | None = None
    ) -> StoredSignoff:
        """Add a record at the end of the log. ``sign(seq, prev_hash)`` returns the record's
        columns (those of :data:`RECORD_COLUMNS`) signed for that place; it is called inside
        the write transaction, which holds the log (SQLite: the write lock; PostgreSQL: an
        advisory lock), so two processes signing at once queue and never take the same
        place. A course database keeps ``evidence``, the bytes of the run record the record
        rests on, with it (a data folder's records stay on its disk). Returns the row as
        stored."""
        postgres = self.rows.postgres
        with self.rows.write() as tx:
            if postgres:
                tx.execute("SELECT pg_advisory_xact_lock(?)", (SIGNOFF_LOCK,))
            # rows whose seq is not a number were tampered with, and so is a row numbered
            # far beyond the log: verify names them, and the log goes on after the run of
            # consecutive numbers it grew by (signlog.next_place)
            numbered = "seq IS NOT NULL" if postgres else "typeof(seq) = 'integer'"
            rows = tx.execute(
                f"SELECT seq, entry_hash FROM signoffs WHERE {numbered} ORDER BY seq"
            ).fetchall()
            seq, prev = next_place([(int(s), str(h or "")) for s, h in rows])
            if seq >= MAX_SEQ:
                raise StoreError(
                    f"{self.rows.where}: the sign-off log claims {seq - 1} records, more than it "
                    "can hold; check it with 'workbench signoff verify'"
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
            new = tx.execute(
                f"INSERT INTO signoffs ({', '.join(columns)}) "
                f"VALUES ({', '.join('?' for _ in columns)}) RETURNING id",
                row,
            ).fetchone()
            row_id = int(new[0])
            if postgres and evidence is not None and draft.evidence_digest:
                kept_at = utc_iso(datetime.now(UTC))
                workspace_rows.keep_evidence(tx, draft.evidence_digest, evidence, kept_at)
        return replace(draft, id=row_id, entry_hash=digest)

    def of(self, student: str | None = None, lab: str | None = None) -> list[StoredSignoff]:
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
        rows = self.rows.read(sql, tuple(params))
        return [signoff_from_row(r, SIGNOFF_COLUMNS) for r in rows]

    def lockout(self, instructor: str) -> LockoutState:
        rows = self.rows.read(
            "SELECT failures, locked_until FROM lockouts WHERE instructor = ?", (instructor,)
        )
        if not rows:
            return LockoutState(0, 0.0)
        return LockoutState(int(rows[0][0]), float(rows[0][1]))

    def record_failure(
        self, instructor: str, now: datetime, limit: int, lock_seconds: float
    ) -> LockoutState:
        """Count a wrong passphrase; the ``limit``-th in a row locks until now + lock_seconds."""
        with self.rows.write() as tx:
            if self.rows.postgres:  # two servers counting one instructor's failures queue
                tx.execute("SELECT pg_advisory_xact_lock(?)", (SIGNOFF_LOCK + 1,))
            row = tx.execute(
                "SELECT failures FROM lockouts WHERE instructor = ?", (instructor,)
            ).fetchone()
            failures = (int(row[0]) if row else 0) + 1
            locked_until = 0.0
            if failures >= limit:
                locked_until = now.timestamp() + lock_seconds
                failures = 0
            tx.execute(
                "INSERT INTO lockouts (instructor, failures, locked_until, updated_at) "
                "VALUES (?, ?, ?, ?) ON CONFLICT (instructor) DO UPDATE SET "
                "failures = excluded.failures, locked_until = excluded.locked_until, "
                "updated_at = excluded.updated_at",
                (instructor, failures, locked_until, utc_iso(now)),
            )
        return LockoutState(failures, locked_until)

    def clear_failures(self, instructor: str, now: datetime) -> None:
        with self.rows.write() as tx:
            tx.execute(
                "UPDATE lockouts SET failures = 0, locked_until = 0, updated_at = ? "
                "WHERE instructor = ?",
                (utc_iso(now), instructor),
            )

    def log_event(self, instructor: str, event: str, detail: str, now: datetime) -> None:
        with self.rows.write() as tx:
            tx.execute(
                "INSERT INTO events (at, instructor, event, detail) VALUES (?, ?, ?, ?)",
                (utc_iso(now), instructor, event, detail),
            )

    def events(self, instructor: str | None = None) -> list[Event]:
        sql = "SELECT at, instructor, event, detail FROM events"
        params: tuple[Any, ...] = ()
        if instructor:
            sql += " WHERE instructor = ?"
            params = (instructor,)
        return [Event(*r) for r in self.rows.read(sql + " ORDER BY id", params)]


def signoff_from_row(row: tuple[Any, ...], names: tuple[str, ...]) -> StoredSignoff:
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
