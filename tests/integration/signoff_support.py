"""Helpers of the sign-off command tests: an instructor, signed records, the database."""

from __future__ import annotations

import io
import re
import sqlite3
import sys
from datetime import UTC, datetime
from pathlib import Path

from workbench.cli import main
from workbench.labs.signoff.instructors import KdfParams
from workbench.labs.signoff.signing import sign_off
from workbench.labs.signoff.signoff_record import Evidence, RecordFields
from workbench.labs.store.store import DB_NAME, Store

PASS = "correct horse battery"
FAST = KdfParams(n=2**10, r=8, p=1)  # cheap scrypt for tests only; defaults are untouched


def add_instructor(monkeypatch, data_dir: Path, name: str, passphrase: str = PASS) -> int:
    monkeypatch.setattr(sys, "stdin", io.StringIO(passphrase + "\n"))
    return main(["instructor", "add", name, "--passphrase-stdin", "--data-dir", str(data_dir)])


def sign(
    data_dir: Path,
    student: str,
    exercise: str,
    partner: str = "",
    when: int = 0,
    instructor: str = "Dr Chen",
    passphrase: str = PASS,
) -> None:
    fields = RecordFields(
        student=student,
        partner=partner,
        driver=student,
        lab="web-simulator",
        exercise=exercise,
        evidence=Evidence("", "", {"collisions": 1}),
        objectives_passed=True,
    )
    moment = datetime(2026, 3, 2, 10, when, tzinfo=UTC)
    with Store.open(data_dir) as store:
        sign_off(store, instructor, passphrase, fields, clock=lambda: moment)


def sql(data_dir: Path, *statements: str, params: tuple = ()) -> list[tuple]:
    """Run statements on the database as someone editing the file would, and close it."""
    conn = sqlite3.connect(data_dir / DB_NAME)
    try:
        rows: list[tuple] = []
        for statement in statements:
            rows = conn.execute(statement, params if "?" in statement else ()).fetchall()
        conn.commit()
        return rows
    finally:
        conn.close()


def head_of(out: str) -> str:
    """The head of the sign-off log (``SEQ:SHA256``) a command printed."""
    found = re.search(r"\bhead (\d+:[0-9a-f]{64})", out)
    assert found is not None, f"no head of the log in:\n{out}"
    return found.group(1)


def fields(run_record: Path | None = None, passed: bool = True, **kw) -> RecordFields:
    """What a sign-off records: alice, driving, with bob on the Unity wall-following exercise;
    as evidence the run record ``run_record`` (none) and an exit in 41.5 s without a collision.
    ``kw`` replaces any of them."""
    evidence = Evidence(
        str(run_record) if run_record else "", "", {"exit_time": 41.5, "collisions": 0}
    )
    base = dict(
        student="alice",
        partner="bob",
        driver="alice",
        lab="unity-simulator",
        exercise="wall-following",
        evidence=evidence,
        objectives_passed=passed,
    )
    base.update(kw)
    return RecordFields(**base)
