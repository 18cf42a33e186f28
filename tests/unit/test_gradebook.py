"""The exported gradebook: one digest format, and the measures of the run each sign-off rests
on, with the unit of its profile."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from tests.app.console_support import progress as drive_by_wire
from tests.app.console_support import wall_main, write_record
from workbench.labs.signoff.gradebook import (
    GRADEBOOK_COLUMNS,
    gradebook_rows,
    run_cells,
    sha256_text,
)
from workbench.labs.signoff.instructors import KdfParams, create_instructor
from workbench.labs.signoff.roster import load_roster, roster_path
from workbench.labs.signoff.signing import sign_off
from workbench.labs.signoff.signoff_record import Evidence, RecordFields
from workbench.labs.signoff.verify import verify_log
from workbench.labs.store.store import Store
from workbench.sim.record import file_sha256

FAST = KdfParams(n=2**10, r=8, p=1)  # cheap scrypt for tests only
PASS = "correct horse battery"
DIGEST = re.compile(r"sha256:[0-9a-f]{64}")


def signed(store: Store, student: str, progress, driver: str = "") -> None:
    fields = RecordFields(
        student=student,
        lab=progress.lab,
        exercise=progress.exercise,
        driver=driver or student,
        evidence=Evidence.of_progress(progress),
        objectives_passed=progress.passed,
    )
    sign_off(store, "Dr Chen", PASS, fields)


@pytest.fixture
def store(tmp_path: Path):
    data = tmp_path / "data"
    create_instructor(data, "Dr Chen", PASS, kdf=FAST)
    with Store.open(data) as s:
        yield s


def test_every_digest_is_written_one_way_and_the_run_has_its_measures(store, tmp_path):
    record = write_record(tmp_path / "run-004.jsonl")
    recorded = wall_main("ana")
    for state in recorded.objectives[:2]:  # the run record is the evidence's: sha256 of it
        state.evidence.update(record=str(record), record_sha256=file_sha256(record))
    signed(store, "ana", recorded)
    signed(store, "ben", wall_main("ben", digest="cd" * 32))  # no record: the evidence's digest
    signed(store, "cat", drive_by_wire())  # saved before programs and blocks were kept
    log = verify_log(store.signoffs.of(), load_roster(roster_path(Path(store.path).parent)))
    profiles = {("unity-simulator", "drive-by-wire"): "unity"}
    rows = {r["student"]: r for r in gradebook_rows(log.verified_rows(), log.head, profiles)}
    assert set(rows["ana"]) == set(GRADEBOOK_COLUMNS)
    assert rows["ana"]["evidence_digest"] == f"sha256:{file_sha256(record)}"
    for row in rows.values():
        assert DIGEST.fullmatch(row["evidence_digest"]), row["evidence_digest"]
    ben = rows["ben"]
    assert (ben["program"], ben["program_sha256"]) == ("wall.viple", "sha256:" + "cd" * 32)
    assert {k: ben[k] for k in ("run", "profile", "time_s", "distance_blocks", "distance",
                                "distance_unit", "turn_degrees", "turns", "collisions")} == {
        "run": "3", "profile": "web", "time_s": "61.25", "distance_blocks": "60.65",
        "distance": "4245", "distance_unit": "px", "turn_degrees": "1980.0", "turns": "22",
        "collisions": "1",
    }  # fmt: skip
    cat = rows["cat"]
    assert (cat["program"], cat["program_sha256"], cat["run"]) == ("", "", "3")
    assert (cat["distance"], cat["distance_unit"], cat["distance_blocks"]) == (
        "12.25", "unit", "6.12",
    )  # fmt: skip
    assert cat["turn_degrees"] == "" and cat["time_s"] == "41.50"


def test_records_without_a_run_leave_its_columns_empty():
    assert set(run_cells({"objectives": [], "evidence_digest": "ab"}).values()) == {""}
    assert set(run_cells({"unreadable": "x"}).values()) == {""}
    bare = run_cells({"exit_time": 41.5, "collisions": 0}, "web")  # signed with bare figures
    assert (bare["time_s"], bare["collisions"], bare["profile"]) == ("41.50", "0", "web")
    assert sha256_text("") == "" and sha256_text("sha256:ab") == sha256_text("ab") == "sha256:ab"
