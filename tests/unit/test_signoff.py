"""Instructor keys, signed sign-off records, lockout and the SQLite store."""

from __future__ import annotations

import json
import os
import signal
import sqlite3
import subprocess
import sys
from dataclasses import replace
from datetime import UTC, datetime
from pathlib import Path

import pytest

from tests.clocks import Clock
from tests.integration.signoff_support import fields
from workbench.labs.signlog import GENESIS, RECORD_FORMAT
from workbench.labs.signoff.gradebook import gradebook_rows
from workbench.labs.signoff.instructors import (
    KdfParams,
    create_instructor,
    key_path,
    unlock_instructor,
)
from workbench.labs.signoff.roster import RosterEntry, load_roster, roster_path
from workbench.labs.signoff.signing import MAX_NOTE, sign_off
from workbench.labs.signoff.signoff_errors import (
    LockedOut,
    PassphraseTooShort,
    SignoffError,
    UnknownInstructor,
    WrongPassphrase,
)
from workbench.labs.signoff.signoff_record import (
    Evidence,
    SignoffRecord,
    record_digest,
    record_from_stored,
)
from workbench.labs.signoff.verify import verify_all, verify_log
from workbench.labs.store.store import (
    DB_NAME,
    SIGNOFF_COLUMNS,
    Store,
    StoreError,
    read_signoffs,
    resolve_data_dir,
)

FAST = KdfParams(n=2**10, r=8, p=1)  # cheap scrypt for tests only; defaults are untouched
PASS = "correct horse battery"
T0 = datetime(2026, 3, 2, 14, 5, 9, tzinfo=UTC)


@pytest.fixture
def data_dir(tmp_path: Path) -> Path:
    return tmp_path / "data"


@pytest.fixture
def store(data_dir: Path):
    create_instructor(data_dir, "Dr Chen", PASS, kdf=FAST)
    with Store.open(data_dir) as s:
        yield s


@pytest.fixture
def run_record(tmp_path: Path) -> Path:
    p = tmp_path / "run.jsonl"
    p.write_text('{"type":"header","format":"workbench-run/1"}\n{"type":"summary"}\n')
    return p


def roster(data_dir: Path) -> dict[str, RosterEntry]:
    return load_roster(roster_path(data_dir))


def problems(store: Store, data_dir: Path) -> list[tuple[str, ...]]:
    return [v.problems for v in verify_all(store, roster(data_dir))]


# keys and roster


def test_default_kdf_is_memory_hard():
    assert KdfParams() == KdfParams(n=2**17, r=8, p=1)


def test_instructor_key_is_encrypted_and_the_public_key_joins_the_roster(data_dir):
    entry = create_instructor(data_dir, "Dr Chen", PASS, kdf=FAST, now=T0)
    key_file = key_path(data_dir, "Dr Chen")
    data = json.loads(key_file.read_text())
    assert data["kdf"]["name"] == "scrypt" and data["kdf"]["n"] == 2**10
    assert data["cipher"]["name"] == "AES-256-GCM"
    assert oct(key_file.stat().st_mode & 0o777) == "0o600"
    assert roster(data_dir)["Dr Chen"] == entry
    assert entry.added == "2026-03-02T14:05:09Z"
    unlocked = unlock_instructor(data_dir, "Dr Chen", PASS)
    assert unlocked.public_key_b64() == entry.public_key


def test_short_passphrase_is_refused_with_the_minimum(data_dir):
    with pytest.raises(PassphraseTooShort, match="at least 10 characters"):
        create_instructor(data_dir, "Dr Chen", "short", kdf=FAST)
    assert not roster_path(data_dir).exists()


def test_same_instructor_twice_and_bad_names_are_refused(data_dir):
    create_instructor(data_dir, "Dr Chen", PASS, kdf=FAST)
    with pytest.raises(SignoffError, match="already in the roster"):
        create_instructor(data_dir, "Dr Chen", PASS, kdf=FAST)
    for bad in ("", "  ", " Dr Chen", "a\tb", "x" * 65):
        with pytest.raises(SignoffError):
            create_instructor(data_dir, bad, PASS, kdf=FAST)


def test_wrong_passphrase_is_a_specific_error(data_dir):
    create_instructor(data_dir, "Dr Chen", PASS, kdf=FAST)
    with pytest.raises(WrongPassphrase, match="wrong passphrase for Dr Chen"):
        unlock_instructor(data_dir, "Dr Chen", "not the passphrase")
    with pytest.raises(UnknownInstructor, match="no key for instructor Dr Who"):
        unlock_instructor(data_dir, "Dr Who", PASS)


def test_a_damaged_roster_is_reported_with_its_file(data_dir):
    data_dir.mkdir()
    roster_path(data_dir).write_text("{not json")
    with pytest.raises(SignoffError, match=r"roster.json: the roster is not JSON"):
        roster(data_dir)


# signing


def test_happy_path_signs_stores_and_verifies(store, data_dir, run_record):
    clock = Clock(T0)
    row_id, record = sign_off(store, "Dr Chen", PASS, fields(run_record), clock=clock)
    assert record.signed_at == "2026-03-02T14:05:09Z"
    assert record.evidence.digest == record_digest(run_record)
    assert record.evidence.digest.startswith("sha256:") and not record.override
    [row] = store.signoffs.of()
    assert row.id == row_id and row.student == "alice" and row.partner == "bob"
    assert record_from_stored(row) == record
    assert problems(store, data_dir) == [()]


def test_canonical_bytes_are_stable_and_cover_every_field(run_record):
    record = SignoffRecord(
        "alice", "", "alice", "lab", "ex", "Dr Chen", "2026-03-02T14:05:09Z", "", False,
        Evidence("r.jsonl", "sha256:00", {"b": 1, "a": 0.5}),
    )  # fmt: skip
    again = replace(record, evidence=Evidence("r.jsonl", "sha256:00", {"a": 0.5, "b": 1}))
    assert record.canonical() == again.canonical()
    assert json.loads(record.canonical())["format"] == "workbench-signoff/1"  # legacy: no place
    placed = replace(record, seq=3, prev=GENESIS)
    data = json.loads(placed.canonical())
    assert data["format"] == RECORD_FORMAT == "workbench-signoff/2"
    assert (data["seq"], data["prev"]) == (3, GENESIS)
    assert set(data) >= {"student", "partner", "driver", "lab", "exercise", "instructor"}
    assert set(data) >= {"signed_at", "note", "override", "evidence"}
    assert placed.canonical() != replace(placed, seq=4).canonical()
    assert placed.canonical() != replace(placed, prev="sha256:" + "1" * 64).canonical()


def test_signing_needs_passed_objectives_or_an_override_with_a_note(store, data_dir):
    with pytest.raises(SignoffError, match="objectives have not all passed"):
        sign_off(store, "Dr Chen", PASS, fields(passed=False))
    with pytest.raises(SignoffError, match="override needs a note"):
        sign_off(store, "Dr Chen", PASS, fields(passed=False), override=True, note="  ")
    assert store.signoffs.of() == []
    _, record = sign_off(
        store, "Dr Chen", PASS, fields(passed=False), override=True, note="timer was off"
    )
    assert record.override and record.note == "timer was off"
    assert problems(store, data_dir) == [()]


def test_bad_record_fields_are_refused(store, tmp_path):
    with pytest.raises(SignoffError, match="student is missing"):
        sign_off(store, "Dr Chen", PASS, fields(student=""))
    with pytest.raises(SignoffError, match="driver carol is neither"):
        sign_off(store, "Dr Chen", PASS, fields(driver="carol"))
    with pytest.raises(SignoffError, match="cannot read the run record"):
        sign_off(store, "Dr Chen", PASS, fields(tmp_path / "missing.jsonl"))
    with pytest.raises(SignoffError, match="cannot be recorded"):
        bad = replace(fields(), evidence=Evidence("", "", {"t": float("nan")}))
        sign_off(store, "Dr Chen", PASS, bad)


def test_a_bare_hex_digest_of_the_run_record_is_accepted(store, run_record):
    bare = record_digest(run_record).removeprefix("sha256:")
    ev = Evidence(str(run_record), bare, {"runs": [{"t": 1.5}]})
    _, record = sign_off(store, "Dr Chen", PASS, replace(fields(), evidence=ev))
    assert record.evidence.digest == f"sha256:{bare}"
    assert record_from_stored(store.signoffs.of()[0]) == record


def test_a_run_record_changed_before_signing_is_refused(store, run_record):
    ev = Evidence(str(run_record), "sha256:" + "0" * 64, {})
    with pytest.raises(SignoffError, match="changed since it was checked"):
        sign_off(store, "Dr Chen", PASS, replace(fields(), evidence=ev))


# lockout


def test_wrong_passphrase_is_rejected_and_logged(store):
    with pytest.raises(WrongPassphrase):
        sign_off(store, "Dr Chen", "wrong wrong wrong", fields(), clock=Clock(T0))
    assert store.signoffs.of() == []
    assert [e.event for e in store.signoffs.events("Dr Chen")] == ["wrong-passphrase"]


def test_five_failures_lock_for_a_minute_even_across_restarts(store, data_dir):
    clock = Clock(T0)
    for _ in range(4):
        with pytest.raises(WrongPassphrase):
            sign_off(store, "Dr Chen", "wrong wrong wrong", fields(), clock=clock)
    with pytest.raises(LockedOut, match="locked for 60 s"):
        sign_off(store, "Dr Chen", "wrong wrong wrong", fields(), clock=clock)
    clock.advance(30)
    with Store.open(data_dir) as reopened, pytest.raises(LockedOut, match="30 s more"):
        sign_off(reopened, "Dr Chen", PASS, fields(), clock=clock)
    assert store.signoffs.of() == []
    events = [e.event for e in store.signoffs.events("Dr Chen")]
    assert events == ["wrong-passphrase"] * 5 + ["locked"]
    clock.advance(31)
    sign_off(store, "Dr Chen", PASS, fields(), clock=clock)
    assert len(store.signoffs.of()) == 1


def test_the_lockout_is_per_instructor_and_a_success_resets_the_count(store, data_dir):
    create_instructor(data_dir, "Dr Lee", "another long passphrase", kdf=FAST)
    clock = Clock(T0)
    for _ in range(5):
        with pytest.raises(SignoffError):
            sign_off(store, "Dr Chen", "wrong wrong wrong", fields(), clock=clock)
    sign_off(store, "Dr Lee", "another long passphrase", fields(), clock=clock)
    clock.advance(61)
    for _ in range(4):
        with pytest.raises(WrongPassphrase):
            sign_off(store, "Dr Chen", "wrong wrong wrong", fields(), clock=clock)
    sign_off(store, "Dr Chen", PASS, fields(), clock=clock)
    assert store.signoffs.lockout("Dr Chen").failures == 0
    with pytest.raises(WrongPassphrase):
        sign_off(store, "Dr Chen", "wrong wrong wrong", fields(), clock=clock)


# verification


@pytest.mark.parametrize(
    ("column", "value"),
    [
        ("note", "great work"),
        ("signed_at", "2026-03-01T09:00:00Z"),
        ("student", "mallory"),
        ("partner", "mallory"),
        ("driver", "bob"),
        ("exercise", "another-exercise"),
        ("override", 1),
        ("evidence_digest", "sha256:" + "1" * 64),
        ("metrics", '{"collisions":0,"exit_time":12.0}'),
        ("instructor", "Dr Lee"),
    ],
)
def test_a_record_edited_in_the_database_fails_verify(store, data_dir, column, value):
    create_instructor(data_dir, "Dr Lee", "another long passphrase", kdf=FAST)
    sign_off(store, "Dr Chen", PASS, fields(), clock=Clock(T0))
    assert problems(store, data_dir) == [()]
    with sqlite3.connect(store.path) as conn:
        conn.execute(f"UPDATE signoffs SET {column} = ?", (value,))
    [found] = problems(store, data_dir)
    assert any("signature does not match" in p for p in found)


def test_a_changed_run_record_fails_and_a_missing_one_is_only_noted(store, data_dir, run_record):
    sign_off(store, "Dr Chen", PASS, fields(run_record), clock=Clock(T0))
    run_record.write_text(run_record.read_text() + '{"t":1}\n')
    [verdict] = verify_all(store, roster(data_dir))
    assert not verdict.ok and "no longer has the signed digest" in verdict.problems[0]
    run_record.unlink()
    [verdict] = verify_all(store, roster(data_dir))
    assert verdict.ok and "not present" in verdict.notes[0]


def test_a_key_not_in_the_roster_fails(store, data_dir, tmp_path):
    other = tmp_path / "elsewhere"
    create_instructor(other, "Dr Fake", PASS, kdf=FAST)
    create_instructor(other, "Dr Chen", PASS, kdf=FAST)
    with Store.open(other) as rogue:
        sign_off(rogue, "Dr Fake", PASS, fields(), clock=Clock(T0))
        sign_off(rogue, "Dr Chen", PASS, fields(), clock=Clock(T0))
    rogue_log = verify_log(read_signoffs(other), roster(data_dir))  # chain and all
    found = [v.problems for v in rogue_log.verdicts]
    assert found[0] == ("instructor 'Dr Fake' is not in the trusted roster",)
    assert len(found[1]) == 1 and "signature does not match" in found[1][0]


def test_gradebook_has_one_row_per_student_and_exercise_from_verified_records(store, data_dir):
    clock = Clock(T0)
    sign_off(store, "Dr Chen", PASS, fields(), clock=clock)
    clock.advance(60)
    sign_off(store, "Dr Chen", PASS, fields(), clock=clock)
    sign_off(store, "Dr Chen", PASS, fields(student="carol", partner="", driver="", exercise="x"))
    sign_off(store, "Dr Chen", PASS, fields(student="dave", partner="", driver=""))
    with sqlite3.connect(store.path) as conn:
        conn.execute("UPDATE signoffs SET note = 'edited' WHERE student = 'dave'")
    log = verify_log(store.signoffs.of(), roster(data_dir))
    rows = gradebook_rows(log.verified_rows(), log.head)
    keys = [(r["student"], r["exercise"]) for r in rows]
    assert keys == [("alice", "wall-following"), ("bob", "wall-following"), ("carol", "x")]
    assert rows[0]["signed_at"] == "2026-03-02T14:06:09Z"
    assert rows[1]["partner"] == "alice"
    assert [r["seq"] for r in rows] == ["2", "2", "3"]
    assert {r["log_head"] for r in rows} == {str(log.head)} and log.head.seq == 4


# the store


def test_data_dir_comes_from_the_option_then_the_environment(monkeypatch, tmp_path):
    monkeypatch.setenv("WORKBENCH_DATA", str(tmp_path / "env"))
    assert resolve_data_dir(str(tmp_path / "opt")) == tmp_path / "opt"
    assert resolve_data_dir(None) == tmp_path / "env"
    monkeypatch.delenv("WORKBENCH_DATA")
    assert resolve_data_dir(None).name == "viple-workbench"


def test_store_uses_wal_and_a_schema_version(data_dir):
    with Store.open(data_dir) as s:
        assert s.schema_version() == 6  # the last step: workspace files
    with sqlite3.connect(data_dir / DB_NAME) as conn:
        assert conn.execute("PRAGMA journal_mode").fetchone()[0] == "wal"


def test_a_corrupt_or_newer_database_is_named_in_the_error(tmp_path):
    bad = tmp_path / "bad"
    bad.mkdir()
    (bad / DB_NAME).write_bytes(b"this is not sqlite at all, just some text" * 50)
    with pytest.raises(StoreError, match=rf"{DB_NAME}: not a readable workbench database"):
        Store.open(bad)
    newer = tmp_path / "newer"
    Store.open(newer).close()
    with sqlite3.connect(newer / DB_NAME) as conn:
        conn.execute("UPDATE meta SET value = '99' WHERE key = 'schema_version'")
    with pytest.raises(StoreError, match="newer workbench"):
        Store.open(newer)


def test_progress_and_drivers_are_saved_and_replaced(data_dir):
    with Store.open(data_dir) as s:
        s.progress.save("alice", "web", "ex1", {"objectives": {"keys": True}}, now=T0)
        s.progress.save("alice", "web", "ex1", {"objectives": {"keys": True, "maze": False}})
        s.progress.save("alice", "unity", "ex2", {"answers": [1]})
        s.progress.set_driver("alice", "bob", "web", "ex1", "alice")
        s.progress.set_driver("alice", "bob", "web", "ex1", "bob")
    with Store.open(data_dir) as s:
        assert s.progress.of("alice", "web") == {
            ("web", "ex1"): {"objectives": {"keys": True, "maze": False}}
        }
        assert len(s.progress.of("alice")) == 2
        assert s.progress.drivers("alice", "bob") == {("web", "ex1"): "bob"}
        with pytest.raises(ValueError):
            s.progress.save("alice", "web", "ex1", {"t": float("inf")})


WRITER = """
import sys
from workbench.labs.store.store import Store
s = Store.open(sys.argv[1])
i = 0
while True:
    s.progress.save("alice", "lab", f"ex{i}", {"i": i})
    print(i, flush=True)
    i += 1
"""


def test_a_killed_process_keeps_what_it_committed(data_dir):
    proc = subprocess.Popen(
        [sys.executable, "-c", WRITER, str(data_dir)],
        stdout=subprocess.PIPE,
        text=True,
        env={**os.environ, "PYTHONPATH": str(Path(__file__).resolve().parents[2])},
    )
    assert proc.stdout is not None
    last = -1
    for line in proc.stdout:
        last = int(line)
        if last >= 30:
            break
    proc.send_signal(signal.SIGKILL)
    proc.wait()
    with Store.open(data_dir) as s:
        saved = s.progress.of("alice")
    assert last >= 30
    assert all(("lab", f"ex{i}") in saved for i in range(last + 1))


def test_evidence_of_an_exercise_points_at_the_run_record_it_rests_on(tmp_path):
    from types import SimpleNamespace

    from workbench.labs.signoff.signoff_record import Evidence, record_digest

    record = tmp_path / "run-001.jsonl"
    record.write_text('{"type":"header"}\n')
    sha = record_digest(record).removeprefix("sha256:")
    progress = SimpleNamespace(
        objectives=[
            SimpleNamespace(kind="keys", passed=True, evidence={"keys": ["w"]}),
            SimpleNamespace(
                kind="exit", passed=True, evidence={"record": str(record), "record_sha256": sha}
            ),
        ],
        evidence_digest=lambda: "abc",
    )
    evidence = Evidence.of_progress(progress)
    assert (evidence.run_record, evidence.digest) == (str(record), sha)
    assert evidence.metrics["evidence_digest"] == "abc"
    assert [o["kind"] for o in evidence.metrics["objectives"]] == ["keys", "exit"]
    progress.objectives[1].passed = False
    assert Evidence.of_progress(progress).run_record == ""


def test_the_sign_off_names_the_program_and_older_records_still_verify(store, data_dir):
    from types import SimpleNamespace

    digest = "ab" * 32
    run = {"run": 2, "driver": "VIPLE program mine.viple", "program_sha256": digest,
           "program_name": "mine.viple", "sensors": ["distance:1:right"]}  # fmt: skip
    progress = SimpleNamespace(
        objectives=[
            SimpleNamespace(kind="sensors", passed=True, evidence=run),
            SimpleNamespace(kind="exit", passed=True, evidence=run),
            SimpleNamespace(kind="questions", passed=True, evidence={"correct": 1, "of": 1}),
        ],
        evidence_digest=lambda: "abc",
    )
    evidence = Evidence.of_progress(progress)
    assert evidence.metrics["programs"] == {digest: "mine.viple"}
    # a record made before the sign-off named its program (no "programs" in its evidence)
    sign_off(store, "Dr Chen", PASS, fields(), clock=Clock(T0))
    _, record = sign_off(store, "Dr Chen", PASS, fields(evidence=evidence), clock=Clock(T0))
    [_, row] = store.signoffs.of()
    assert row.metrics_value()["programs"] == {digest: "mine.viple"}
    assert record_from_stored(row) == record
    assert problems(store, data_dir) == [(), ()]


# the chained log in the store

V1_SCHEMA = """
CREATE TABLE meta (key TEXT PRIMARY KEY, value TEXT NOT NULL);
INSERT INTO meta VALUES ('schema_version', '1');
CREATE TABLE signoffs (
    id INTEGER PRIMARY KEY AUTOINCREMENT, student TEXT NOT NULL, partner TEXT NOT NULL,
    driver TEXT NOT NULL, lab TEXT NOT NULL, exercise TEXT NOT NULL, instructor TEXT NOT NULL,
    signed_at TEXT NOT NULL, note TEXT NOT NULL, override INTEGER NOT NULL,
    run_record TEXT NOT NULL, evidence_digest TEXT NOT NULL, metrics TEXT NOT NULL,
    signature TEXT NOT NULL
);
"""


def v1_database(data_dir: Path, students: list[str]) -> None:
    """A database as the workbench wrote it before the log was chained (schema 1)."""
    signer = unlock_instructor(data_dir, "Dr Chen", PASS)
    conn = sqlite3.connect(data_dir / DB_NAME)
    conn.executescript(V1_SCHEMA)
    for n, student in enumerate(students):
        record = SignoffRecord(
            student, "", student, "web-simulator", f"ex{n}", "Dr Chen",
            f"2026-01-0{n + 1}T10:00:00Z", "", False, Evidence("", "sha256:00", {"n": n}),
        )  # fmt: skip
        columns = record.columns(signer.sign(record.canonical()))
        columns["override"] = int(columns["override"])
        conn.execute(
            f"INSERT INTO signoffs ({', '.join(columns)}) VALUES ({', '.join('?' * len(columns))})",
            tuple(columns.values()),
        )
    conn.commit()
    conn.close()


def test_records_made_before_the_chain_are_read_as_legacy_then_chained_by_the_upgrade(data_dir):
    create_instructor(data_dir, "Dr Chen", PASS, kdf=FAST)
    v1_database(data_dir, ["ana", "ben"])
    before = (data_dir / DB_NAME).read_bytes()
    read_only = verify_log(read_signoffs(data_dir), roster(data_dir))
    assert read_only.ok and read_only.legacy == 2 and read_only.head.seq == 2
    assert all("legacy record" in v.notes[0] for v in read_only.verdicts)
    assert (data_dir / DB_NAME).read_bytes() == before  # reading did not upgrade it
    with Store.open(data_dir) as store:
        assert store.schema_version() == 6
        assert store.signoffs.of() == read_signoffs(data_dir)  # upgraded to what was read
        sign_off(store, "Dr Chen", PASS, fields(), clock=Clock(T0))
        log = verify_log(store.signoffs.of(), roster(data_dir), kept=read_only.head)
    assert log.ok and log.legacy == 2 and log.head.seq == 3
    assert [v.row.legacy for v in log.verdicts] == [True, True, False]
    sql_edit = "UPDATE signoffs SET student = 'zed' WHERE seq = 1"
    with sqlite3.connect(data_dir / DB_NAME) as conn:
        conn.execute(sql_edit)
    conn.close()
    [first, *_] = verify_log(read_signoffs(data_dir), roster(data_dir)).verdicts
    assert any("signature does not match" in p for p in first.problems)


def test_a_sequence_number_is_taken_once(store):
    sign_off(store, "Dr Chen", PASS, fields(), clock=Clock(T0))
    with sqlite3.connect(store.path) as conn, pytest.raises(sqlite3.IntegrityError):
        conn.execute(
            "INSERT INTO signoffs (student, partner, driver, lab, exercise, instructor, "
            "signed_at, note, override, run_record, evidence_digest, metrics, signature, seq) "
            "SELECT student, partner, driver, lab, exercise, instructor, signed_at, note, "
            "override, run_record, evidence_digest, metrics, signature, seq FROM signoffs"
        )
    conn.close()


SIGNER = """
import os, sys, time
from datetime import UTC, datetime
from workbench.labs.signoff.signing import sign_off
from workbench.labs.signoff.signoff_record import RecordFields
from workbench.labs.store.store import Store
data_dir, who, ready = sys.argv[1], sys.argv[2], sys.argv[3]
fields = RecordFields(student=who, lab="lab", exercise="ex", objectives_passed=True)
with Store.open(data_dir) as store:
    open(os.path.join(ready, who), "w").close()  # ready; both begin once both are
    while len(os.listdir(ready)) < 2:
        time.sleep(0.001)
    for i in range(12):
        sign_off(store, "Dr Chen", "correct horse battery", fields)
"""


def test_two_processes_signing_at_once_never_fork_the_chain(store, data_dir, tmp_path):
    ready = tmp_path / "ready"  # each signer says it is ready here, and waits for the other
    ready.mkdir()
    env = {**os.environ, "PYTHONPATH": str(Path(__file__).resolve().parents[2])}
    procs = [
        subprocess.Popen([sys.executable, "-c", SIGNER, str(data_dir), who, str(ready)], env=env)
        for who in ("alice", "bob")
    ]
    assert [p.wait(timeout=120) for p in procs] == [0, 0]
    rows = read_signoffs(data_dir)
    assert [r.seq for r in rows] == list(range(1, 25))
    assert sorted(r.student for r in rows) == ["alice"] * 12 + ["bob"] * 12
    log = verify_log(rows, roster(data_dir))
    assert log.ok, (log.breaks, [v.problems for v in log.verdicts if not v.ok])


def test_signing_after_a_tampered_sequence_number_goes_on_or_says_why(store, data_dir):
    sign_off(store, "Dr Chen", PASS, fields(), clock=Clock(T0))
    sign_off(store, "Dr Chen", PASS, fields(), clock=Clock(T0))
    with sqlite3.connect(store.path) as conn:
        conn.execute("UPDATE signoffs SET seq = 'last' WHERE seq = 2")
    conn.close()
    _, record = sign_off(store, "Dr Chen", PASS, fields(), clock=Clock(T0))
    assert record.seq == 2  # after the last numbered record; verify names the damaged one
    log = verify_log(read_signoffs(data_dir), roster(data_dir))
    assert [v.row.label() for v in log.verdicts if not v.ok] == ["row id 2"]
    with sqlite3.connect(store.path) as conn:
        conn.execute("UPDATE signoffs SET seq = ? WHERE id = 3", (2**62,))
    conn.close()
    _, record = sign_off(store, "Dr Chen", PASS, fields(), clock=Clock(T0))
    assert record.seq == 2  # the far-off number is stepped over, not followed


def test_a_planted_row_with_a_huge_sequence_number_is_stepped_over_and_named(store, data_dir):
    for _ in range(3):
        sign_off(store, "Dr Chen", PASS, fields(), clock=Clock(T0))
    with sqlite3.connect(store.path) as conn:  # a copy of record 3, planted far beyond the log
        columns = ", ".join(c for c in SIGNOFF_COLUMNS if c not in ("id", "seq"))
        conn.execute(
            f"INSERT INTO signoffs ({columns}, seq) SELECT {columns}, 999999999999999999 "
            "FROM signoffs WHERE seq = 3"
        )
    conn.close()
    signed = [sign_off(store, "Dr Chen", PASS, fields(), clock=Clock(T0))[1] for _ in range(2)]
    assert [r.seq for r in signed] == [4, 5]
    log = verify_log(read_signoffs(data_dir), roster(data_dir))
    assert [v.row.seq for v in log.verdicts if not v.ok] == [999999999999999999]
    assert any("before sequence 999999999999999999" in b for b in log.breaks), log.breaks


def test_a_note_longer_than_the_cap_is_refused_and_nothing_is_signed(store, run_record):
    with pytest.raises(SignoffError, match=f"keep it to {MAX_NOTE}"):
        sign_off(store, "Dr Chen", PASS, fields(run_record), note="x" * (8 << 20))
    assert store.signoffs.of() == []
    _, record = sign_off(store, "Dr Chen", PASS, fields(run_record), note="y" * MAX_NOTE)
    assert record.note == "y" * MAX_NOTE
