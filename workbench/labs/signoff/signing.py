"""Making a sign-off: an instructor's passphrase unlocks their key, which signs the record
that joins the log.

Wrong passphrases are counted per instructor in the store: the fifth in a row locks signing by
that instructor for a minute, and each is written to the store's event log. Unlocking the key
runs scrypt (~128 MiB, a fraction of a second), so signing comes in three steps: check
(:func:`prepare_signoff`), unlock (:meth:`PendingSignoff.unlock`, which touches no store and
may run in a thread) and complete (:meth:`PendingSignoff.complete`); :func:`sign_off` takes
them one after the other.
"""

from __future__ import annotations

import hashlib
import json
import logging
import os
from collections.abc import Callable
from dataclasses import dataclass, replace
from datetime import UTC, datetime
from typing import Any

from ..store.store import Store, utc_iso
from ..store.workspace_rows import EVIDENCE_CAP, evidence_copies
from .instructors import Instructor, SealedKey, read_key
from .signoff_errors import LockedOut, SignoffError, WrongPassphrase
from .signoff_record import (
    Evidence,
    RecordFields,
    SignoffRecord,
    canonical_json,
    name_problems,
    record_digest,
)

log = logging.getLogger(__name__)

FAILURE_LIMIT = 5
#: the longest note a sign-off keeps, in characters
MAX_NOTE = 500
LOCK_SECONDS = 60.0


def _now() -> datetime:
    return datetime.now(UTC)


def _check_fields(
    fields: RecordFields, store: Store | None = None
) -> tuple[Evidence, bytes | None]:
    """The evidence as it will be signed, and the run record's bytes when they were read
    (for a course database to keep with the record)."""
    for label, value in (
        ("student", fields.student),
        ("lab", fields.lab),
        ("exercise", fields.exercise),
    ):
        if not value.strip():
            raise SignoffError(f"the {label} is missing")
    for problem in name_problems(fields.student, fields.partner):
        raise SignoffError(problem)
    people = {fields.student, fields.partner} - {""}
    if fields.driver and fields.driver not in people:
        raise SignoffError(f"the driver {fields.driver} is neither the student nor the partner")
    ev = fields.evidence
    if not isinstance(ev.metrics, dict):
        raise SignoffError("the evidence metrics must be a mapping")
    metrics = json.loads(canonical_json(ev.metrics))
    digest = ev.digest
    data: bytes | None = None
    if ev.run_record:
        expected = digest if not digest or digest.startswith("sha256:") else f"sha256:{digest}"
        if store is not None and store.postgres and expected and not os.path.exists(ev.run_record):
            actual, data = _stored_copy(store, fields, expected)
        elif store is not None and store.postgres:
            actual, data = _read_record(ev.run_record)
        else:
            actual = record_digest(ev.run_record)
        if expected and expected != actual:
            raise SignoffError(
                f"{ev.run_record}: the run record changed since it was checked "
                f"(digest {actual}, expected {expected})"
            )
        digest = actual
    return Evidence(str(ev.run_record), digest, metrics), data


def _read_record(path: str) -> tuple[str, bytes | None]:
    """A run record's digest, and its bytes when it is small enough to keep a copy of."""
    try:
        with open(path, "rb") as fh:
            data = fh.read(EVIDENCE_CAP + 1)
    except OSError as exc:
        raise SignoffError(f"{path}: cannot read the run record: {exc.strerror}") from None
    if len(data) > EVIDENCE_CAP:
        return record_digest(path), None
    return f"sha256:{hashlib.sha256(data).hexdigest()}", data


def _stored_copy(store: Store, fields: RecordFields, expected: str) -> tuple[str, bytes]:
    """The digest and bytes of the run record's copy in the course store (a served student's
    record kept on another lab server): the copy with the ``expected`` digest when there is
    one, else the copy at the record's place. :class:`SignoffError` when the store holds no
    copy."""
    record = fields.evidence.run_record
    copies = evidence_copies(store.read, record, expected, (fields.student, fields.partner))
    digests = [(f"sha256:{hashlib.sha256(data).hexdigest()}", data) for _, _, data in copies]
    for found in digests:
        if found[0] == expected:
            return found
    if digests:
        return digests[0]
    raise SignoffError(
        f"{record}: the run record is neither on this machine nor in the course store (it "
        "is kept on the lab server where it was made until it is sent)"
    )


def sign_off(
    store: Store,
    instructor: str,
    passphrase: str,
    record_fields: RecordFields,
    override: bool = False,
    note: str = "",
    *,
    clock: Callable[[], datetime] = _now,
    say: Callable[[str], None] | None = None,
) -> tuple[int, SignoffRecord]:
    """Sign and store a record; returns its id and the record. ``say`` is told of each slow
    step as it begins (unlocking the key, signing), for a screen that shows them.

    Allowed when ``record_fields.objectives_passed`` or with ``override`` (which needs a note).
    Raises :class:`LockedOut` while locked, :class:`WrongPassphrase` (counted: the fifth in a
    row locks this instructor for a minute), :class:`UnknownInstructor`, or
    :class:`SignoffError`. Every step may wait (for the store, for scrypt): an app calls it
    in a thread.
    """
    pending = prepare_signoff(store, instructor, record_fields, override, note, clock=clock)
    if say is not None:
        say(f"unlocking the key of {instructor}...")
    signer = pending.unlock(passphrase)
    if signer is not None and say is not None:
        say(f"signing as {instructor}...")
    return pending.complete(signer)


@dataclass(frozen=True)
class PendingSignoff:
    """A sign-off that is checked and waits only for the instructor's key to be unlocked."""

    store: Store
    record: SignoffRecord
    key: SealedKey
    #: wrong passphrases in a row before this attempt
    failures: int
    now: datetime
    #: the run record's bytes, kept with the record in a course database
    evidence: bytes | None = None

    def unlock(self, passphrase: str) -> Instructor | None:
        """The instructor, their key opened with ``passphrase``; None when it is the wrong
        one. The slow step (scrypt); it touches neither the store nor anything else, so it is
        the one to run off an event loop."""
        try:
            return self.key.unlock(passphrase)
        except WrongPassphrase:
            return None

    def complete(self, signer: Instructor | None) -> tuple[int, SignoffRecord]:
        """Sign and store the record with the unlocked key, returning its id and the record;
        or, given None (a wrong passphrase), count the failure and raise
        :class:`WrongPassphrase`, or :class:`LockedOut` when it was one too many."""
        store, record, now = self.store, self.record, self.now
        instructor = record.instructor
        if signer is None:
            after = store.signoffs.record_failure(instructor, now, FAILURE_LIMIT, LOCK_SECONDS)
            where = f"{record.student} {record.lab}/{record.exercise}"
            store.signoffs.log_event(instructor, "wrong-passphrase", where, now)
            log.info("wrong passphrase for instructor %s at %s", instructor, where)
            if after.locked_until:
                store.signoffs.log_event(instructor, "locked", f"for {LOCK_SECONDS:g} s", now)
                log.info("sign-off by %s locked for %g s", instructor, LOCK_SECONDS)
                raise LockedOut(instructor, LOCK_SECONDS, FAILURE_LIMIT)
            raise WrongPassphrase(f"wrong passphrase for {instructor}")
        if self.failures:
            store.signoffs.clear_failures(instructor, now)

        def sign_at(seq: int, prev: str) -> dict[str, Any]:
            placed = replace(record, seq=seq, prev=prev)
            return placed.columns(signer.sign(placed.canonical()))

        stored = store.signoffs.append(sign_at, self.evidence)
        return stored.id, replace(record, seq=stored.seq, prev=stored.prev_hash)


def prepare_signoff(
    store: Store,
    instructor: str,
    record_fields: RecordFields,
    override: bool = False,
    note: str = "",
    *,
    clock: Callable[[], datetime] = _now,
) -> PendingSignoff:
    """Check a sign-off before the passphrase is tried: the fields and evidence, the override
    and its note, the lock, and the instructor's key (read, still sealed). Raises
    :class:`LockedOut`, :class:`UnknownInstructor` or :class:`SignoffError`."""
    note = note.strip()
    if len(note) > MAX_NOTE:
        raise SignoffError(
            f"the note is {len(note)} characters: keep it to {MAX_NOTE} (a sentence or two)"
        )
    if not record_fields.objectives_passed and not override:
        raise SignoffError("the objectives have not all passed: sign off with an override")
    if override and not note:
        raise SignoffError("an override needs a note saying why")
    evidence, data = _check_fields(record_fields, store)
    now = clock()
    state = store.signoffs.lockout(instructor)
    if state.locked_until > now.timestamp():
        raise LockedOut(instructor, state.locked_until - now.timestamp(), FAILURE_LIMIT)
    key = read_key(store.data_dir, instructor, store)
    record = SignoffRecord(
        student=record_fields.student,
        partner=record_fields.partner,
        driver=record_fields.driver,
        lab=record_fields.lab,
        exercise=record_fields.exercise,
        instructor=instructor,
        signed_at=utc_iso(now),
        note=note,
        override=override,
        evidence=evidence,
    )
    return PendingSignoff(store, record, key, state.failures, now, data)
