"""The gradebook: the sign-off log exported as CSV, one row per student and exercise.

Every row carries the record's place in the log and the log's head at export, so a kept
gradebook is also a kept head: ``workbench signoff verify --head-from`` reads it back. Each
row also has the measures of the run the sign-off rests on (time, distance in blocks and in
the profile's unit, named in ``distance_unit``, turning, turns, collisions) and the program
that drove it. Every digest is written one way: ``sha256:`` and 64 hex digits (empty where
there is none).
"""

from __future__ import annotations

import csv
from collections.abc import Mapping
from pathlib import Path
from typing import Any

from ..evidence_text import measures_of, program_of
from ..signlog import Head, LogError
from ..store.store import StoredSignoff
from .signoff_errors import SignoffError

#: the columns of the run a sign-off rests on: the program that drove it and its measures
RUN_COLUMNS = (
    "program",
    "program_sha256",
    "run",
    "profile",
    "time_s",
    "distance_blocks",
    "distance",
    "distance_unit",
    "turn_degrees",
    "turns",
    "collisions",
)
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
    *RUN_COLUMNS,
    "seq",
    "log_head",
)

#: how a length in each unit is written in the gradebook (decimals), as the screens round it
DECIMALS = {"px": 0, "unit": 2}


def sha256_text(digest: str) -> str:
    """A digest as the gradebook writes every digest: ``sha256:`` and its hex ("" for none)."""
    return f"sha256:{digest.removeprefix('sha256:')}" if digest else ""


def evidence_run(metrics: Any) -> Mapping[str, Any] | None:
    """The run a signed record's evidence rests on: the first passed objective's evidence
    that has a run's figures; a record signed with bare figures (no objectives) is its own."""
    if not isinstance(metrics, Mapping):
        return None
    objectives = metrics.get("objectives")
    if not isinstance(objectives, list):
        return {"metrics": metrics} if "exit_time" in metrics or "distance" in metrics else None
    for objective in objectives:
        if not isinstance(objective, Mapping) or not objective.get("passed"):
            continue
        evidence = objective.get("evidence")
        if isinstance(evidence, Mapping) and isinstance(evidence.get("metrics"), Mapping):
            return evidence
    return None


def _figure(value: float | int | None, decimals: int) -> str:
    return "" if value is None else f"{value:.{decimals}f}"


def run_cells(metrics: Any, profile: str = "") -> dict[str, str]:
    """The gradebook's run columns for a record's evidence (empty where it has no run);
    ``profile`` is the exercise's, for evidence that names none."""
    run = evidence_run(metrics)
    cells = dict.fromkeys(RUN_COLUMNS, "")
    if run is None:
        return cells
    program = program_of(run)
    if program is not None:
        cells["program"], cells["program_sha256"] = program[1], sha256_text(program[0])
    m = measures_of(run, profile)
    run_number = run.get("run")
    cells["run"] = str(run_number) if isinstance(run_number, int) else ""
    cells["profile"] = str(run.get("profile") or profile)
    if m is not None:
        cells.update(
            time_s=_figure(m.time, 2),
            distance_blocks=_figure(m.blocks, 2),
            distance=_figure(m.distance, DECIMALS.get(m.unit, 2)),
            distance_unit=m.unit if m.distance is not None else "",
            turn_degrees=_figure(m.turn_degrees, 1),
            turns=_figure(m.turns, 0),
            collisions=_figure(m.collisions, 0),
        )
    return cells


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


def gradebook_rows(
    rows: list[StoredSignoff],
    head: Head,
    profiles: Mapping[tuple[str, str], str] | None = None,
) -> list[dict[str, str]]:
    """One row per student and exercise (each member of a pair gets one); the latest wins,
    except that a record which only names a person as partner never replaces a row of their
    own request (see :mod:`.partners`). Every row carries the record's place in the log, the
    log's head at export, and the measures of the evidence run (lengths in the unit of its
    profile, else of the exercise's in ``profiles``)."""
    latest: dict[tuple[str, str, str], dict[str, str]] = {}
    own: set[tuple[str, str, str]] = set()
    for row in rows:
        run = run_cells(row.metrics_value(), (profiles or {}).get((row.lab, row.exercise), ""))
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
                "evidence_digest": sha256_text(row.evidence_digest),
                **run,
                "seq": "" if row.seq is None else str(row.seq),
                "log_head": str(head),
            }
    return [latest[k] for k in sorted(latest)]
