"""Checking the sign-off log: each record's signature against a trusted roster, its
students' names and run record, and the hash chain that links the records.

The roster used must be one the instructor holds (:func:`.roster.trusted_roster_path`): the
data folder's copy is passed only to explain a record signed with a key it gives.
"""

from __future__ import annotations

import base64
import binascii
import hashlib
import os
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass, replace

from cryptography.exceptions import InvalidSignature

from .. import signlog
from ..signlog import Head
from ..store import workspace_rows
from ..store.database import PostgresBackend
from ..store.store import Store, StoredSignoff, StoreError
from .roster import RosterEntry
from .signoff_errors import SignoffError
from .signoff_record import name_problems, record_digest

#: the copies of a record's run record the course store holds: (student, path, bytes) each
#: (see :func:`.workspace_rows.evidence_copies`); raises StoreError when it cannot be asked
EvidenceLookup = Callable[[StoredSignoff], list[tuple[str, str, bytes]]]


@dataclass(frozen=True)
class Verdict:
    row: StoredSignoff
    problems: tuple[str, ...]
    notes: tuple[str, ...]

    @property
    def ok(self) -> bool:
        return not self.problems


@dataclass(frozen=True)
class LogVerdict:
    """The log checked as a whole: its head, breaks in the chain (records missing, a head
    the instructor kept that the log no longer holds) and each record's verdict."""

    head: Head
    breaks: tuple[str, ...]
    verdicts: tuple[Verdict, ...]
    legacy: int

    @property
    def ok(self) -> bool:
        return not self.breaks and all(v.ok for v in self.verdicts)

    def verified_rows(self) -> list[StoredSignoff]:
        return [v.row for v in self.verdicts if v.ok]


def _signature_problem(
    row: StoredSignoff,
    roster: dict[str, RosterEntry],
    local: dict[str, RosterEntry] | None,
) -> str | None:
    entry = roster.get(row.instructor)
    if entry is None:
        return f"instructor {row.instructor!r} is not in the trusted roster"
    if _signed_by(row, entry):
        return None
    other = (local or {}).get(row.instructor)
    if other is not None and other.public_key != entry.public_key and _signed_by(row, other):
        return (
            f"signed with a key the data folder's roster gives for {row.instructor} "
            f"({other.fingerprint()}), not the trusted one ({entry.fingerprint()}): the "
            "instructor was re-keyed in the data folder"
        )
    return (
        f"the signature does not match the record (changed after signing, or not signed by "
        f"{row.instructor}'s key in the trusted roster)"
    )


def _signed_by(row: StoredSignoff, entry: RosterEntry) -> bool:
    try:
        signature = base64.b64decode(row.signature, validate=True)
        entry.key().verify(signature, row.signed_bytes())
    except (InvalidSignature, binascii.Error, ValueError):
        return False
    return True


def verify_row(
    row: StoredSignoff,
    roster: dict[str, RosterEntry],
    local: dict[str, RosterEntry] | None = None,
    evidence: EvidenceLookup | None = None,
) -> Verdict:
    """Check one stored record: its signature by the trusted roster's key, its students'
    names, and its run record if present, on this machine or else in the course store
    (``evidence``) (its place in the log is checked by :func:`verify_log`). ``local`` is the
    data folder's roster, used only to explain a signature by a key that is not the trusted
    one."""
    problems: list[str] = []
    notes: list[str] = []
    signature = _signature_problem(row, roster, local)
    if signature:
        problems.append(signature)
    problems.extend(name_problems(row.student, row.partner))
    if row.legacy:
        notes.append(
            "legacy record (signed before the log was chained): its signature covers its "
            "fields, its place in the log was given when the database was upgraded"
        )
    if row.run_record:
        if os.path.exists(row.run_record):
            try:
                actual = record_digest(row.run_record)
            except SignoffError as exc:
                problems.append(str(exc))
            else:
                if actual != row.evidence_digest:
                    problems.append(
                        f"the run record {row.run_record} no longer has the signed digest"
                    )
        elif evidence is not None:
            _check_stored_record(row, evidence, problems, notes)
        else:
            notes.append(f"run record {row.run_record} not present: its digest was not checked")
    return Verdict(row, tuple(problems), tuple(notes))


def _check_stored_record(
    row: StoredSignoff, evidence: EvidenceLookup, problems: list[str], notes: list[str]
) -> None:
    """The run record not on this machine: checked against the course store's copies."""
    try:
        copies = evidence(row)
    except StoreError as exc:
        notes.append(
            f"run record {row.run_record} not present, and the course store could not be "
            f"asked ({exc}): its digest was not checked"
        )
        return
    for student, path, data in copies:
        if f"sha256:{hashlib.sha256(data).hexdigest()}" == row.evidence_digest:
            notes.append(
                f"run record {row.run_record} not on this machine: its digest was checked in "
                f"the course store ({_copy_words(student, path)})"
            )
            return
    if copies:
        student, path, _ = copies[0]
        problems.append(
            f"the run record {row.run_record} no longer has the signed digest (the course "
            f"store's copy, {_copy_words(student, path)})"
        )
        return
    notes.append(
        f"run record {row.run_record} not present here nor in the course store: its digest "
        "was not checked"
    )


def _copy_words(student: str, path: str) -> str:
    return f"{student}'s ~/{path}" if path else "the copy kept when it was signed"


@contextmanager
def course_evidence(db: str | None) -> Iterator[EvidenceLookup | None]:
    """The run records kept in the course database ``db`` (students' workspace files), read
    in a read-only session; None without a course database (a data folder's records are on
    its own disk)."""
    if not db:
        yield None
        return
    backend = PostgresBackend(db, read_only=True)

    def lookup(row: StoredSignoff) -> list[tuple[str, str, bytes]]:
        people = (row.student, row.partner)
        return workspace_rows.evidence_copies(
            backend.read, row.run_record, row.evidence_digest, people
        )

    try:
        yield lookup
    finally:
        backend.close()


def _entry(row: StoredSignoff) -> signlog.Entry:
    return signlog.Entry(
        id=row.id,
        seq=row.seq,
        prev=row.prev_hash,
        stored_hash=row.entry_hash,
        legacy=row.legacy,
        signed=row.signed_bytes(),
        signature=row.signature,
    )


def verify_log(
    rows: list[StoredSignoff],
    roster: dict[str, RosterEntry],
    kept: Head | None = None,
    local: dict[str, RosterEntry] | None = None,
    evidence: EvidenceLookup | None = None,
) -> LogVerdict:
    """Check the whole log (``rows`` in the order of the log): every record and the chain
    that links them, and, given the head the instructor kept, that the log still holds it.
    ``evidence`` finds the run records not on this machine in the course store."""
    chain = signlog.check_chain([_entry(r) for r in rows], kept)
    verdicts = []
    for row in rows:
        own = verify_row(row, roster, local, evidence)
        linked = chain.by_row.get(row.id, ())
        verdicts.append(replace(own, problems=(*linked, *own.problems)))
    legacy = sum(1 for r in rows if r.legacy)
    return LogVerdict(chain.head, chain.breaks, tuple(verdicts), legacy)


def verify_all(store: Store, roster: dict[str, RosterEntry]) -> list[Verdict]:
    """Every record of an open store, checked with its place in the log."""
    return list(verify_log(store.signoffs.of(), roster).verdicts)


def log_head(rows: list[StoredSignoff]) -> Head:
    """The head of a log as stored (``rows`` in the order of the log), checked or not."""
    return signlog.check_chain([_entry(r) for r in rows]).head
