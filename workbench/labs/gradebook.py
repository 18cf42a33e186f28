"""The gradebook: the sign-off log exported as CSV, one row per student and exercise.

Every row carries the record's place in the log and the log's head at export, so a kept
gradebook is also a kept head: ``workbench signoff verify --head-from`` reads it back.
"""

from __future__ import annotations

import csv
from pathlib import Path

from .signlog import Head, LogError
from .signoff_errors import SignoffError
from .store import StoredSignoff

GRADEBOOK_COLUMNS = (
    "student",
    "partner",
    "lab",
    "exercise",
    "signed_at",
    "instructor",
    "driver",
    "override",
    "note",
    "evidence_digest",
    "seq",
    "log_head",
)


def head_from_gradebook(path: Path) -> Head:
    """The log head kept in an exported gradebook (its ``log_head`` column)."""
    try:
        with path.open(encoding="utf-8", newline="") as fh:
            heads = {row.get("log_head") or "" for row in csv.DictReader(fh)}
    except OSError as exc:
        raise SignoffError(f"{path}: cannot read the gradebook: {exc.strerror}") from None
    except (csv.Error, UnicodeDecodeError) as exc:
        raise SignoffError(f"{path}: not a gradebook CSV ({exc})") from None
    heads.discard("")
    if len(heads) != 1:
        found = "no log_head column" if not heads else "different log heads in its rows"
        raise SignoffError(
            f"{path}: {found}; give the head itself with --head SEQ:HASH (as 'workbench "
            "signoff verify' or 'export' printed it)"
        )
    try:
        return Head.parse(heads.pop(), f"{path}: the log head")
    except LogError as exc:
        raise SignoffError(str(exc)) from None


def gradebook_rows(rows: list[StoredSignoff], head: Head) -> list[dict[str, str]]:
    """One row per student and exercise (each member of a pair gets one); the latest wins,
    except that a record which only names a person as partner never replaces a row of their
    own request (see :mod:`.partners`). Every row carries the record's place in the log and
    the log's head at export."""
    latest: dict[tuple[str, str, str], dict[str, str]] = {}
    own: set[tuple[str, str, str]] = set()
    for row in rows:
        for person, other in ((row.student, row.partner), (row.partner, row.student)):
            if not person:
                continue
            key = (person, row.lab, row.exercise)
            if person == row.student:
                own.add(key)
            elif key in own:
                continue
            latest[key] = {
                "student": person,
                "partner": other,
                "lab": row.lab,
                "exercise": row.exercise,
                "signed_at": row.signed_at,
                "instructor": row.instructor,
                "driver": row.driver,
                "override": "yes" if row.override else "no",
                "note": row.note,
                "evidence_digest": row.evidence_digest,
                "seq": "" if row.seq is None else str(row.seq),
                "log_head": str(head),
            }
    return [latest[k] for k in sorted(latest)]
