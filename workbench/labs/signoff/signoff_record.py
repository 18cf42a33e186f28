"""What an instructor signs: a sign-off record, the evidence it rests on, and its bytes.

A record is turned into canonical JSON bytes (:meth:`SignoffRecord.canonical`) and signed;
checking rebuilds the same bytes from the stored columns, so changing any of them breaks the
signature. The records form the hash-chained log of :mod:`.signlog`.
"""

from __future__ import annotations

import os
from dataclasses import dataclass, field
from typing import Any

from workbench.sim.record import file_sha256

from .. import signlog
from ..evidence_text import programs_of
from ..names import NameProblem, check_student
from ..store.store import StoredSignoff
from .signoff_errors import SignoffError


@dataclass(frozen=True)
class Evidence:
    """What a sign-off rests on: the run record (path and SHA-256 of its bytes) and metrics."""

    run_record: str = ""
    digest: str = ""
    metrics: dict[str, Any] = field(default_factory=dict)

    @classmethod
    def of_progress(cls, progress: Any) -> Evidence:
        """The evidence of an exercise's checks (an ``ExerciseProgress``): the run record of
        the first passing objective that rests on one, every objective's evidence with the
        digest of them all, and (as ``programs``: digest -> file name) the programs the
        evidence rests on. Records made before ``programs`` was kept lack it and verify as
        they did."""
        objectives = [
            {"kind": o.kind, "passed": o.passed, "evidence": o.evidence}
            for o in progress.objectives
        ]
        metrics = {"objectives": objectives, "evidence_digest": progress.evidence_digest()}
        programs = programs_of(progress)
        if programs:  # the program the evidence rests on (more than one: it mixes them)
            metrics["programs"] = programs
        for o in progress.objectives:
            record, sha = o.evidence.get("record"), o.evidence.get("record_sha256")
            if o.passed and record and sha:
                return cls(run_record=str(record), digest=sha, metrics=metrics)
        return cls(run_record="", digest=progress.evidence_digest(), metrics=metrics)


@dataclass(frozen=True)
class RecordFields:
    """What the caller knows when asking for a sign-off."""

    student: str
    lab: str
    exercise: str
    driver: str = ""
    partner: str = ""
    evidence: Evidence = field(default_factory=Evidence)
    objectives_passed: bool = False


@dataclass(frozen=True)
class SignoffRecord:
    """What an instructor signs: the fields, the evidence, and the record's place in the log
    (``seq`` and the hash of the record before it; ``seq`` is ``None`` for a legacy record)."""

    student: str
    partner: str
    driver: str
    lab: str
    exercise: str
    instructor: str
    signed_at: str
    note: str
    override: bool
    evidence: Evidence
    seq: int | None = None
    prev: str = ""

    def canonical(self) -> bytes:
        """The exact bytes that are signed: sorted-key compact JSON, UTF-8."""
        evidence = {
            "run_record": self.evidence.run_record,
            "digest": self.evidence.digest,
            "metrics": self.evidence.metrics,
        }
        return signlog.signed_payload(self.__dict__, evidence, self.seq, self.prev)

    def columns(self, signature: str) -> dict[str, Any]:
        return {
            "student": self.student,
            "partner": self.partner,
            "driver": self.driver,
            "lab": self.lab,
            "exercise": self.exercise,
            "instructor": self.instructor,
            "signed_at": self.signed_at,
            "note": self.note,
            "override": self.override,
            "run_record": self.evidence.run_record,
            "evidence_digest": self.evidence.digest,
            "metrics": canonical_json(self.evidence.metrics),
            "signature": signature,
        }


def canonical_json(value: Any) -> str:
    try:
        return signlog.canonical_json(value)
    except (TypeError, ValueError) as exc:
        raise SignoffError(f"the evidence cannot be recorded: {exc}") from None


def record_digest(path: str | os.PathLike) -> str:
    """The evidence digest of a run record: ``sha256:`` and the hex SHA-256 of its bytes."""
    try:
        return f"sha256:{file_sha256(path)}"
    except OSError as exc:
        raise SignoffError(f"{path}: cannot read the run record: {exc.strerror}") from None


def record_from_stored(row: StoredSignoff) -> SignoffRecord:
    return SignoffRecord(
        student=row.student,
        partner=row.partner,
        driver=row.driver,
        lab=row.lab,
        exercise=row.exercise,
        instructor=row.instructor,
        signed_at=row.signed_at,
        note=row.note,
        override=row.override,
        evidence=Evidence(row.run_record, row.evidence_digest, row.metrics_value()),
        seq=None if row.legacy else row.seq,
        prev="" if row.legacy else row.prev_hash,
    )


def name_problems(student: str, partner: str) -> list[str]:
    """Why the names of a record's students are not ones the workbench accepts, if they are
    not: look-alike, invisible or not normalised."""
    problems = []
    for what, value in (("student", student), ("partner", partner)):
        if not value:
            continue
        try:
            clean = check_student(value, what)
        except NameProblem as exc:
            problems.append(f"{exc} ({value!r})")
            continue
        if clean != value:
            problems.append(f"the {what}'s name {value!r} is not in normal form ({clean!r})")
    return problems
