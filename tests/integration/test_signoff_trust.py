"""`workbench signoff verify` and `export` against someone who can write the data folder:
records deleted, copied, reordered, inserted or rolled back, the table dropped, an instructor
re-keyed or imitated. Each is found (exit 1, naming the record or the break); the untouched
log verifies, and checking changes nothing on disk."""

from __future__ import annotations

import csv
import json
import shutil
from dataclasses import replace
from pathlib import Path

import pytest
from cryptography.hazmat.primitives.asymmetric.ed25519 import Ed25519PrivateKey

from workbench.cli import main
from workbench.labs.signlog import GENESIS, entry_hash
from workbench.labs.signoff.instructors import Instructor, create_instructor, key_path
from workbench.labs.signoff.roster import load_roster, roster_path
from workbench.labs.signoff.signoff_record import record_from_stored
from workbench.labs.store.store import DB_NAME, Store, read_signoffs

from .signoff_support import FAST, add_instructor, head_of, sign, sql


@pytest.fixture
def three(data_dir) -> Path:
    for n, student in enumerate(("alice", "bob", "carol")):
        sign(data_dir, student, "sensors", when=n)
    return data_dir


def run(capsys, *args: str) -> tuple[int, str]:
    code = main(list(args))
    captured = capsys.readouterr()
    return code, captured.out + captured.err


def verify(capsys, data_dir: Path, *extra: str) -> tuple[int, str]:
    return run(capsys, "signoff", "verify", *extra, "--data-dir", str(data_dir))


def relink(data_dir: Path) -> None:
    """Recompute every link and hash after an edit, as someone without a key can."""
    prev = GENESIS
    for row in read_signoffs(data_dir):
        digest = entry_hash(row.seq or 0, prev, row.signed_bytes(), row.signature)
        sql(
            data_dir,
            "UPDATE signoffs SET prev_hash = ?, entry_hash = ? WHERE id = ?",
            params=(prev, digest, row.id),
        )
        prev = digest


def snapshot(folder: Path) -> dict[str, tuple[bytes, int]]:
    """Every file's bytes and time, but SQLite's shared-memory and write-ahead companions,
    which any reader of a WAL database may create (they hold no records of their own)."""
    return {
        p.name: (p.read_bytes(), p.stat().st_mtime_ns)
        for p in folder.iterdir()
        if p.is_file() and not p.name.endswith(("-shm", "-wal"))
    }


def test_an_untouched_log_verifies_and_checking_changes_nothing(three, tmp_path, capsys):
    before = snapshot(three)
    code, out = verify(capsys, three)
    assert code == 0, out
    assert "all 3 record(s) verify" in out and "chain" in out
    head = head_of(out)
    assert head.startswith("3:")
    grades = tmp_path / "grades.csv"
    code, out = run(capsys, "signoff", "export", "--csv", str(grades), "--data-dir", str(three))
    assert code == 0 and head_of(out) == head
    assert run(capsys, "signoff", "list", "--data-dir", str(three))[0] == 0
    assert snapshot(three) == before  # the database file: same bytes, same time; nothing new
    assert (three / DB_NAME).stat().st_size == len(before[DB_NAME][0])
    wal = three / f"{DB_NAME}-wal"
    assert not wal.exists() or wal.stat().st_size == 0  # nothing written ahead either
    rows = list(csv.DictReader(grades.open()))
    assert {r["log_head"] for r in rows} == {head}
    assert [r["seq"] for r in rows] == ["1", "2", "3"]
    assert verify(capsys, three, "--head", head)[0] == 0
    assert verify(capsys, three, "--head-from", str(grades))[0] == 0


def test_verify_never_creates_a_database(data_dir, tmp_path, capsys):
    empty = tmp_path / "nothing-here"
    code, out = verify(capsys, empty)
    assert code == 1 and "no workbench database here" in out
    assert not empty.exists()


def test_a_deleted_record_is_found_where_it_was(three, capsys):
    sql(three, "DELETE FROM signoffs WHERE seq = 2")
    code, out = verify(capsys, three)
    assert code == 1
    assert "FAIL log: the log breaks before sequence 3: record(s) 2 are missing" in out
    assert "FAIL #3 carol sensors" not in out  # (the lab is printed as lab/exercise)
    assert "FAIL #3 carol web-simulator/sensors: it does not follow the record before" in out
    assert "the log does NOT verify" in out


def test_a_duplicated_record_is_found_even_with_its_links_recomputed(three, capsys):
    columns = "student, partner, driver, lab, exercise, instructor, signed_at, note, override, "
    columns += "run_record, evidence_digest, metrics, signature"
    sql(
        three,
        f"INSERT INTO signoffs ({columns}, seq, legacy) SELECT {columns}, 4, 0 FROM signoffs "
        "WHERE seq = 1",
    )
    relink(three)
    code, out = verify(capsys, three)
    assert code == 1
    assert "FAIL #4 alice web-simulator/sensors: the signature does not match" in out
    assert "it is a copy of the record with id 1" in out
    assert "1 of 4 record(s) do NOT verify" in out


def test_reordered_records_are_found(three, capsys):
    sql(
        three,
        "UPDATE signoffs SET seq = -1 WHERE seq = 1",
        "UPDATE signoffs SET seq = 1 WHERE seq = 2",
        "UPDATE signoffs SET seq = 2 WHERE seq = -1",
    )
    code, out = verify(capsys, three)
    assert code == 1
    assert "FAIL #1 bob" in out and "FAIL #2 alice" in out


def test_a_record_inserted_with_another_key_is_found(three, tmp_path, capsys):
    rogue = tmp_path / "rogue"
    create_instructor(rogue, "Dr Chen", "a student's passphrase", kdf=FAST)
    sign(rogue, "mallory", "sensors", passphrase="a student's passphrase")
    [forged] = read_signoffs(rogue)
    values = {k: v for k, v in forged.__dict__.items() if k not in ("id", "seq")}
    with Store.open(three) as store:
        store.signoffs.append(lambda seq, prev: values)
    code, out = verify(capsys, three)
    assert code == 1
    assert "FAIL #4 mallory web-simulator/sensors: the signature does not match" in out


def test_a_rolled_back_database_is_found_with_the_kept_head(data_dir, tmp_path, capsys):
    sign(data_dir, "alice", "sensors")
    sign(data_dir, "bob", "sensors", when=1)
    backup = tmp_path / "old.sqlite3"
    shutil.copy(data_dir / DB_NAME, backup)  # the store is closed: one file holds it all
    sign(data_dir, "carol", "sensors", when=2)
    grades = tmp_path / "grades.csv"
    code, out = run(capsys, "signoff", "export", "--csv", str(grades), "--data-dir", str(data_dir))
    kept = head_of(out)
    shutil.copy(backup, data_dir / DB_NAME)  # carol's sign-off is gone
    assert verify(capsys, data_dir)[0] == 0  # the older log is a sound log in itself ...
    for extra in (("--head", kept), ("--head-from", str(grades))):
        code, out = verify(capsys, data_dir, *extra)  # ... but not the one the head names
        assert code == 1
        assert "the log ends at sequence 2 but the kept head is at 3" in out
        assert "rolled back" in out
    code, out = run(
        capsys, "signoff", "export", "--csv", str(tmp_path / "g2.csv"), "--head", kept,
        "--data-dir", str(data_dir),
    )  # fmt: skip
    assert code == 1 and "no gradebook was written" in out
    assert not (tmp_path / "g2.csv").exists()


def test_a_dropped_table_or_a_deleted_database_is_a_failure(three, tmp_path, capsys):
    code, out = verify(capsys, three)
    kept = head_of(out)
    sql(three, "DROP TABLE signoffs")
    code, out = verify(capsys, three, "--head", kept)
    assert code == 1
    assert "the sign-off table is missing: the log was deleted" in out
    assert "all 0" not in out
    (three / DB_NAME).unlink()
    code, out = verify(capsys, three)
    assert code == 1 and "no workbench database here" in out
    code, out = run(capsys, "signoff", "export", "--csv", str(tmp_path / "g.csv"), "--data-dir",
                    str(three))  # fmt: skip
    assert code == 1 and not (tmp_path / "g.csv").exists()


def test_an_empty_log_says_so_and_fails_against_a_kept_head(data_dir, capsys):
    code, out = verify(capsys, data_dir)
    assert code == 0
    assert f"the log is empty: no sign-off records (head 0:{'0' * 64})" in out
    code, out = verify(capsys, data_dir, "--head", "1:" + "ab" * 32)
    assert code == 1 and "the log ends at sequence 0 but the kept head is at 1" in out


def test_the_data_folders_roster_alone_is_not_trusted(three, tmp_path, monkeypatch, capsys):
    monkeypatch.setenv("WORKBENCH_CONFIG", str(tmp_path / "empty-config"))
    code, out = verify(capsys, three)
    assert code == 1
    assert "no trusted roster" in out and "is not trusted on its own" in out
    assert "--roster FILE" in out and "the records were NOT checked" in out
    code, out = verify(capsys, three, "--roster", str(three / "roster.json"))
    assert code == 1 and "is inside the data folder" in out
    monkeypatch.setenv("WORKBENCH_CONFIG", str(three))
    code, out = verify(capsys, three)
    assert code == 1 and "is inside the data folder" in out
    code, out = run(capsys, "signoff", "export", "--csv", str(tmp_path / "g.csv"), "--data-dir",
                    str(three))  # fmt: skip
    assert code == 1 and not (tmp_path / "g.csv").exists()


def test_an_instructor_re_keyed_in_the_data_folder_fails_and_is_not_exported(
    data_dir, config_dir, tmp_path, capsys
):
    sign(data_dir, "alice", "sensors")
    # a student replaces Dr Chen's key pair in the data folder with one of their own
    key_path(data_dir, "Dr Chen").unlink()
    roster_path(data_dir).unlink()
    create_instructor(data_dir, "Dr Chen", "a student's passphrase", kdf=FAST)
    sign(data_dir, "bob", "sensors", when=1, passphrase="a student's passphrase")
    code, out = verify(capsys, data_dir)
    assert code == 1
    assert "FAIL #2 bob web-simulator/sensors: signed with a key the data folder's roster" in out
    assert "re-keyed" in out and "FAIL #1" not in out
    grades = tmp_path / "grades.csv"
    code, out = run(capsys, "signoff", "export", "--csv", str(grades), "--data-dir", str(data_dir))
    assert code == 0 and "1 record(s) do not verify and were left out" in out
    assert [r["student"] for r in csv.DictReader(grades.open())] == ["alice"]
    code, out = run(capsys, "instructor", "list", "--data-dir", str(data_dir))
    assert "KEY DIFFERS from your trusted roster" in out


@pytest.mark.parametrize(
    ("name", "reason"),
    [
        ("Dr Rіvera", "mixes letters of different scripts (Cyrillic, Latin)"),
        ("Dr Ριvera", "mixes letters of different scripts (Greek, Latin)"),
        ("Dr\u200bChen", "invisible formatting characters (U+200B at position 3)"),
        ("Dr Chen\u202e", "invisible formatting characters (U+202E"),
        ("Dr\u3164Chen", "invisible character (U+1160"),
        ("Dr  Chen", "two spaces in a row"),
    ],
)
def test_look_alike_and_invisible_instructor_names_are_refused(
    data_dir, monkeypatch, capsys, name, reason
):
    assert add_instructor(monkeypatch, data_dir, name) == 2
    assert reason in capsys.readouterr().err
    assert list(load_roster(roster_path(data_dir))) == ["Dr Chen"]


def test_names_are_normalised_when_added(tmp_path, monkeypatch, capsys, config_dir):
    d = tmp_path / "fresh"
    assert add_instructor(monkeypatch, d, "Ｄｒ Ｌｅｅ") == 0  # full-width letters
    assert "added Dr Lee" in capsys.readouterr().out
    assert list(load_roster(config_dir / "roster.json")) == ["Dr Lee"]
    assert add_instructor(monkeypatch, d, "Dr Lee") == 2  # the same name


def test_a_roster_holding_a_look_alike_name_is_refused(three, config_dir, capsys):
    path = config_dir / "roster.json"
    data = json.loads(path.read_text())
    data["instructors"].append({**data["instructors"][0], "name": "Dr Сhen"})
    path.write_text(json.dumps(data))
    code, out = verify(capsys, three)
    assert code == 2
    assert "instructor #2 'Dr Сhen': the instructor's name mixes letters" in out


def test_a_record_by_a_look_alike_instructor_is_not_a_grade(three, tmp_path, capsys):
    impostor = Instructor("Dr Сhen", Ed25519PrivateKey.generate())  # a Cyrillic С
    [genuine] = read_signoffs(three)[:1]
    fields = record_from_stored(genuine)

    def signed(seq: int, prev: str) -> dict:
        record = replace(fields, student="dave", instructor="Dr Сhen", seq=seq, prev=prev)
        return record.columns(impostor.sign(record.canonical()))

    with Store.open(three) as store:
        store.signoffs.append(signed)
    code, out = verify(capsys, three)
    assert code == 1
    assert "FAIL #4 dave web-simulator/sensors: instructor 'Dr Сhen' is not in the trusted" in out
