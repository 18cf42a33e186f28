"""The sign-off queue: students asking for an instructor, in the order they asked.

A student (or pair) asks for sign-off of one exercise from their labs screen; the request waits
in the store's ``signoff_queue`` table until an instructor signs the exercise off or declines it
with a note, or the student withdraws it. The table has one row per student and exercise: asking
again after a decline puts the exercise back at the end of the queue, asking while it waits
keeps its place. Because the queue is in the store, the instructor's console sees the requests
of students on every lab server that shares a PostgreSQL store.

The functions here take a transaction (:class:`~workbench.labs.store.database.Tx`) or a read
function; :class:`QueueRows` (the store's ``queue``) gives them theirs.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from datetime import UTC, datetime
from typing import Any

from .database import StoreError, Tx
from .rows import Rows

#: the states of a request
WAITING, SIGNED, DECLINED, WITHDRAWN = "waiting", "signed", "declined", "withdrawn"
STATES = (WAITING, SIGNED, DECLINED, WITHDRAWN)
#: the longest note a decline keeps (as a sign-off's note), and the longest lab or exercise id
MAX_NOTE = 500
MAX_ID = 100

TABLE = """
CREATE TABLE IF NOT EXISTS signoff_queue (
    id {id},
    student TEXT NOT NULL,
    partner TEXT NOT NULL,
    driver TEXT NOT NULL,
    lab TEXT NOT NULL,
    exercise TEXT NOT NULL,
    state TEXT NOT NULL,
    requested_at TEXT NOT NULL,
    decided_at TEXT NOT NULL,
    instructor TEXT NOT NULL,
    note TEXT NOT NULL
);
CREATE UNIQUE INDEX IF NOT EXISTS signoff_queue_by_exercise
    ON signoff_queue (student, lab, exercise);
CREATE INDEX IF NOT EXISTS signoff_queue_by_state ON signoff_queue (state, requested_at)
"""

COLUMNS = (
    "id",
    "student",
    "partner",
    "driver",
    "lab",
    "exercise",
    "state",
    "requested_at",
    "decided_at",
    "instructor",
    "note",
)
SELECT = f"SELECT {', '.join(COLUMNS)} FROM signoff_queue"

Read = Callable[[str, tuple[Any, ...]], list[tuple[Any, ...]]]


@dataclass(frozen=True)
class QueueEntry:
    """One request for sign-off, as stored."""

    id: int
    student: str
    partner: str
    driver: str
    lab: str
    exercise: str
    state: str
    #: when the student asked (UTC, ISO 8601 to the microsecond: the queue's order)
    requested_at: str
    #: when an instructor signed or declined it ("" while it waits)
    decided_at: str
    instructor: str
    #: the instructor's note with a decline
    note: str

    @property
    def pair(self) -> str:
        """``ana`` or ``ana and ben``."""
        return self.student + (f" and {self.partner}" if self.partner else "")


@dataclass(frozen=True)
class QueueState:
    """Where one student's request for one exercise stands."""

    #: the request (None: never asked)
    entry: QueueEntry | None
    #: its place in the queue, from 1, while it waits (None otherwise)
    place: int | None = None
    #: how many requests wait in all
    waiting: int = 0


def stamp(now: datetime | None = None) -> str:
    """A moment as the queue keeps it: UTC ISO 8601 to the microsecond, which sorts as text."""
    moment = (now or datetime.now(UTC)).astimezone(UTC)
    return moment.isoformat(timespec="microseconds").replace("+00:00", "Z")


def _entry(row: tuple[Any, ...]) -> QueueEntry:
    data = dict(zip(COLUMNS, row, strict=True))
    return QueueEntry(
        id=int(data.pop("id")), **{k: "" if v is None else str(v) for k, v in data.items()}
    )


def _check_ids(lab: str, exercise: str) -> None:
    for label, value in (("lab", lab), ("exercise", exercise)):
        if not value or len(value) > MAX_ID or not value.isprintable():
            raise StoreError(
                f"the {label} id {value[:MAX_ID]!r} is not one a lab file gives "
                f"(1 to {MAX_ID} printable characters)"
            )


def request(
    tx: Tx, student: str, partner: str, driver: str, lab: str, exercise: str, now: datetime
) -> QueueEntry:
    """Ask for sign-off: a request that already waits keeps its place (the names are brought
    up to date); any other is (re)queued at the end."""
    _check_ids(lab, exercise)
    if not student:
        raise StoreError("a request for sign-off needs the student's name")
    row = tx.execute(
        f"{SELECT} WHERE student = ? AND lab = ? AND exercise = ?", (student, lab, exercise)
    ).fetchone()
    if row is None:
        tx.execute(
            "INSERT INTO signoff_queue (student, partner, driver, lab, exercise, state, "
            "requested_at, decided_at, instructor, note) VALUES (?, ?, ?, ?, ?, ?, ?, '', '', '')",
            (student, partner, driver, lab, exercise, WAITING, stamp(now)),
        )
    elif _entry(row).state == WAITING:
        tx.execute(
            "UPDATE signoff_queue SET partner = ?, driver = ? WHERE id = ?",
            (partner, driver, int(row[0])),
        )
    else:
        tx.execute(
            "UPDATE signoff_queue SET partner = ?, driver = ?, state = ?, requested_at = ?, "
            "decided_at = '', instructor = '', note = '' WHERE id = ?",
            (partner, driver, WAITING, stamp(now), int(row[0])),
        )
    new = tx.execute(
        f"{SELECT} WHERE student = ? AND lab = ? AND exercise = ?", (student, lab, exercise)
    ).fetchone()
    return _entry(new)


def withdraw(tx: Tx, student: str, lab: str, exercise: str, now: datetime) -> bool:
    """Take back a waiting request; False when none waited."""
    rows = tx.execute(
        "UPDATE signoff_queue SET state = ?, decided_at = ? "
        "WHERE student = ? AND lab = ? AND exercise = ? AND state = ? RETURNING id",
        (WITHDRAWN, stamp(now), student, lab, exercise, WAITING),
    ).fetchall()
    return bool(rows)


def decide(
    tx: Tx, entry_id: int, state: str, instructor: str, note: str, now: datetime
) -> QueueEntry:
    """Close a waiting request as signed or declined (a decline needs a note, which the student
    sees). Refused when the request no longer waits: another instructor decided it, or the
    student withdrew it."""
    if state not in (SIGNED, DECLINED):
        raise ValueError(f"a request is decided as signed or declined, not {state!r}")
    note = note.strip()
    if state == DECLINED and not note:
        raise StoreError("a decline needs a note telling the student what to do")
    if len(note) > MAX_NOTE:
        raise StoreError(f"the note is {len(note)} characters: keep it to {MAX_NOTE}")
    row = tx.execute(f"{SELECT} WHERE id = ?", (entry_id,)).fetchone()
    if row is None:
        raise StoreError(f"request {entry_id} is not in the sign-off queue")
    entry = _entry(row)
    if entry.state != WAITING:
        who = f" by {entry.instructor}" if entry.instructor else ""
        raise StoreError(
            f"{entry.pair}'s request for {entry.lab}/{entry.exercise} was already "
            f"{entry.state}{who}"
        )
    tx.execute(
        "UPDATE signoff_queue SET state = ?, decided_at = ?, instructor = ?, note = ? WHERE id = ?",
        (state, stamp(now), instructor, note, entry_id),
    )
    new = tx.execute(f"{SELECT} WHERE id = ?", (entry_id,)).fetchone()
    return _entry(new)


def waiting(read: Read) -> list[QueueEntry]:
    """The requests that wait, first asked first."""
    rows = read(f"{SELECT} WHERE state = ? ORDER BY requested_at, id", (WAITING,))
    return [_entry(r) for r in rows]


def state_of(read: Read, student: str, lab: str, exercise: str) -> QueueState:
    """Where ``student``'s request for ``lab``/``exercise`` stands, with its place."""
    rows = read(
        f"{SELECT} WHERE student = ? AND lab = ? AND exercise = ?", (student, lab, exercise)
    )
    count = int(read("SELECT COUNT(*) FROM signoff_queue WHERE state = ?", (WAITING,))[0][0])
    if not rows:
        return QueueState(None, None, count)
    entry = _entry(rows[0])
    if entry.state != WAITING:
        return QueueState(entry, None, count)
    ahead = read(
        "SELECT COUNT(*) FROM signoff_queue WHERE state = ? AND "
        "(requested_at < ? OR (requested_at = ? AND id < ?))",
        (WAITING, entry.requested_at, entry.requested_at, entry.id),
    )
    return QueueState(entry, int(ahead[0][0]) + 1, count)


class QueueRows:
    """The sign-off queue over the store's connection. Every call needs the database:
    :class:`~workbench.labs.store.database.StoreUnavailable` while it is away."""

    def __init__(self, rows: Rows) -> None:
        self.rows = rows

    def request(
        self,
        student: str,
        partner: str,
        driver: str,
        lab: str,
        exercise: str,
        now: datetime | None = None,
    ) -> QueueState:
        """Ask for an instructor's sign-off of ``lab``/``exercise``; returns where the request
        stands (its place in the queue)."""
        with self.rows.write() as tx:
            request(tx, student, partner, driver, lab, exercise, now or datetime.now(UTC))
        return self.state(student, lab, exercise)

    def withdraw(self, student: str, lab: str, exercise: str, now: datetime | None = None) -> bool:
        """Take back a waiting request; False when none waited."""
        with self.rows.write() as tx:
            return withdraw(tx, student, lab, exercise, now or datetime.now(UTC))

    def waiting(self) -> list[QueueEntry]:
        """The requests that wait for an instructor, first asked first."""
        return waiting(self.rows.read)

    def state(self, student: str, lab: str, exercise: str) -> QueueState:
        """Where ``student``'s request for ``lab``/``exercise`` stands."""
        return state_of(self.rows.read, student, lab, exercise)

    def decline(
        self, entry_id: int, instructor: str, note: str, now: datetime | None = None
    ) -> QueueEntry:
        """Decline a waiting request with a note the student sees; refused when it no longer
        waits or the note is empty."""
        with self.rows.write() as tx:
            return decide(tx, entry_id, DECLINED, instructor, note, now or datetime.now(UTC))

    def mark_signed(
        self, entry_id: int, instructor: str, now: datetime | None = None
    ) -> QueueEntry:
        """Close a waiting request once its exercise is signed off."""
        with self.rows.write() as tx:
            return decide(tx, entry_id, SIGNED, instructor, "", now or datetime.now(UTC))
