"""`workbench instructor` and `workbench signoff` as an instructor runs them."""

from __future__ import annotations

import csv
import io
import resource
import signal
import sqlite3
import subprocess
import sys

import pytest

from workbench.cli import main
from workbench.labs.signoff.instructors import create_instructor, unlock_instructor
from workbench.labs.signoff.roster import load_roster, roster_path
from workbench.labs.signoff.signing import sign_off
from workbench.labs.signoff.signoff_record import Evidence, RecordFields
from workbench.labs.store.store import DB_NAME, Store

from .signoff_support import FAST, PASS, add_instructor, sign


def test_instructor_add_with_the_default_kdf_and_list(tmp_path, monkeypatch, capsys, config_dir):
    d = tmp_path / "fresh"
    assert add_instructor(monkeypatch, d, "Prof. Ada Lovelace") == 0
    out = capsys.readouterr().out
    assert "added Prof. Ada Lovelace" in out and "encrypted" in out
    assert f"trusted roster {config_dir / 'roster.json'}" in out
    assert unlock_instructor(d, "Prof. Ada Lovelace", PASS).name == "Prof. Ada Lovelace"
    kept = load_roster(config_dir / "roster.json")["Prof. Ada Lovelace"]
    assert kept == load_roster(roster_path(d))["Prof. Ada Lovelace"]
    assert main(["instructor", "list", "--data-dir", str(d)]) == 0
    assert "Prof. Ada Lovelace" in capsys.readouterr().out


def test_instructor_add_reads_the_environment_data_dir(tmp_path, monkeypatch, capsys):
    monkeypatch.setenv("WORKBENCH_DATA", str(tmp_path / "env"))
    monkeypatch.setattr(sys, "stdin", io.StringIO(PASS + "\n"))
    assert main(["instructor", "add", "Dr Env", "--passphrase-stdin"]) == 0
    assert "Dr Env" in load_roster(tmp_path / "env" / "roster.json")


def test_instructor_add_refuses_short_passphrases_and_duplicates(data_dir, monkeypatch, capsys):
    assert add_instructor(monkeypatch, data_dir, "Dr Lee", "short") == 2
    assert "at least 10 characters" in capsys.readouterr().err
    assert add_instructor(monkeypatch, data_dir, "Dr Chen") == 2
    assert "already in the roster" in capsys.readouterr().err


def test_instructor_add_asks_twice_on_a_terminal(data_dir, monkeypatch, capsys):
    answers = iter([PASS, PASS + "x"])
    monkeypatch.setattr(sys, "stdin", io.StringIO(""))
    monkeypatch.setattr(sys.stdin, "isatty", lambda: True)
    monkeypatch.setattr("getpass.getpass", lambda prompt="": next(answers))
    assert main(["instructor", "add", "Dr Lee", "--data-dir", str(data_dir)]) == 2
    assert "the two passphrases differ" in capsys.readouterr().err
    assert "Dr Lee" not in load_roster(roster_path(data_dir))


def test_instructor_add_without_a_terminal_says_what_to_do(data_dir, monkeypatch, capsys):
    monkeypatch.setattr(sys, "stdin", io.StringIO(""))
    assert main(["instructor", "add", "Dr Lee", "--data-dir", str(data_dir)]) == 2
    assert "--passphrase-stdin" in capsys.readouterr().err


def test_list_filters_by_student_and_lab(data_dir, capsys):
    sign(data_dir, "alice", "sensors", partner="bob")
    sign(data_dir, "carol", "sensors")
    assert main(["signoff", "list", "--student", "bob", "--data-dir", str(data_dir)]) == 0
    out = capsys.readouterr().out
    assert "alice & bob" in out and "carol" not in out
    assert main(["signoff", "list", "--lab", "unity-simulator", "--data-dir", str(data_dir)]) == 0
    assert "no sign-off records match" in capsys.readouterr().out


def test_verify_says_what_it_checks_and_lists_every_failure(data_dir, capsys):
    sign(data_dir, "alice", "sensors")
    sign(data_dir, "bob", "sensors")
    sign(data_dir, "carol", "sensors")
    assert main(["signoff", "verify", "--data-dir", str(data_dir)]) == 0
    out = capsys.readouterr().out
    assert "signature" in out and "digest" in out and "all 3 record(s) verify" in out
    with sqlite3.connect(data_dir / DB_NAME) as conn:
        conn.execute("UPDATE signoffs SET signed_at = '2026-01-01T00:00:00Z' WHERE id = 1")
        conn.execute("UPDATE signoffs SET student = 'mallory' WHERE id = 3")
    assert main(["signoff", "verify", "--data-dir", str(data_dir)]) == 1
    out = capsys.readouterr().out
    assert "FAIL #1 alice" in out and "FAIL #3 mallory" in out and "#2" not in out
    assert "2 of 3 record(s) do NOT verify" in out


def test_verify_against_another_roster(data_dir, tmp_path, capsys):
    sign(data_dir, "alice", "sensors")
    course = tmp_path / "course"
    create_instructor(course, "Dr Chen", PASS, kdf=FAST)  # same name, different key
    roster = str(roster_path(course))
    assert main(["signoff", "verify", "--roster", roster, "--data-dir", str(data_dir)]) == 1
    assert "not the trusted one" in capsys.readouterr().out
    assert main(["signoff", "verify", "--roster", "nope.json", "--data-dir", str(data_dir)]) == 2
    assert "no such roster file" in capsys.readouterr().err


def test_export_contains_exactly_the_verifying_records(data_dir, tmp_path, capsys):
    sign(data_dir, "alice", "sensors", partner="bob", when=1)
    sign(data_dir, "alice", "sensors", partner="bob", when=2)
    sign(data_dir, "carol", "wall-following")
    sign(data_dir, "dave", "sensors")
    with sqlite3.connect(data_dir / DB_NAME) as conn:
        conn.execute("UPDATE signoffs SET note = 'all done' WHERE student = 'dave'")
    target = tmp_path / "grades.csv"
    code = main(["signoff", "export", "--csv", str(target), "--data-dir", str(data_dir)])
    captured = capsys.readouterr()
    assert code == 0
    assert "wrote 3 row(s)" in captured.out and "1 record(s) do not verify" in captured.err
    rows = list(csv.DictReader(target.open()))
    assert [(r["student"], r["exercise"]) for r in rows] == [
        ("alice", "sensors"),
        ("bob", "sensors"),
        ("carol", "wall-following"),
    ]
    assert rows[0]["signed_at"] == "2026-03-02T10:02:00Z" and rows[0]["instructor"] == "Dr Chen"
    header = target.read_text().splitlines()[0].split(",")
    assert header[header.index("evidence_digest") + 1 :][:5] == [
        "program", "program_sha256", "run", "profile", "time_s",
    ]  # fmt: skip
    assert "distance_unit" in header and header[-2:] == ["seq", "log_head"]


def test_a_damaged_database_does_not_verify_and_bad_input_exits_2(data_dir, tmp_path, capsys):
    broken = tmp_path / "broken"
    broken.mkdir()
    (broken / DB_NAME).write_text("not a database " * 100)
    assert main(["signoff", "verify", "--data-dir", str(broken)]) == 1
    err = capsys.readouterr().err
    assert f"{broken / DB_NAME}: not a readable workbench database" in err
    assert "the log does NOT verify" in err
    target = tmp_path / "g.csv"
    assert main(["signoff", "export", "--csv", str(target), "--data-dir", str(broken)]) == 1
    assert not target.exists()
    assert main(["signoff", "list", "--data-dir", str(broken)]) == 2
    (data_dir / "roster.json").write_text("[]")
    assert main(["instructor", "list", "--data-dir", str(data_dir)]) == 2
    assert "not a roster" in capsys.readouterr().err
    for bad in (["--head", "12"], ["--head-from", str(tmp_path / "none.csv")]):
        assert main(["signoff", "verify", *bad, "--data-dir", str(data_dir)]) == 2
    err = capsys.readouterr().err
    assert "--head '12' is not SEQ:HASH" in err and "cannot read the gradebook" in err
    with pytest.raises(SystemExit) as exc:
        main(["signoff"])
    assert exc.value.code == 2


def test_export_to_an_unwritable_place_exits_2(data_dir, tmp_path, capsys):
    target = tmp_path / "no-such-dir" / "g.csv"
    assert main(["signoff", "export", "--csv", str(target), "--data-dir", str(data_dir)]) == 2
    assert "cannot write" in capsys.readouterr().err


def test_a_data_folder_without_a_database_is_reported_not_created(tmp_path, capsys):
    missing = tmp_path / "typo"
    assert main(["signoff", "list", "--data-dir", str(missing)]) == 2
    assert "no workbench database here" in capsys.readouterr().err
    assert not missing.exists()


def _no_room_to_write() -> None:
    """A full disk for this process: no file may grow (SQLite's companion files need to)."""
    signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
    resource.setrlimit(resource.RLIMIT_FSIZE, (0, resource.RLIM_INFINITY))


def test_a_disk_that_fails_is_named_and_never_calls_an_intact_store_unreadable(data_dir):
    sign(data_dir, "ana", "connect")
    before = (data_dir / DB_NAME).read_bytes()
    for command in (["store", "info"], ["signoff", "verify"], ["signoff", "list"]):
        done = subprocess.run(
            [sys.executable, "-m", "workbench", *command, "--data-dir", str(data_dir)],
            capture_output=True, text=True, timeout=60, preexec_fn=_no_room_to_write,
        )  # fmt: skip
        assert done.returncode != 0, command
        assert "an input/output error on the disk" in done.stderr, (command, done.stderr)
        assert "check the disk and its free space" in done.stderr
        assert "restore" not in done.stderr.replace("do not restore", "")
        assert "not a readable" not in done.stderr
        if command[1] == "verify":
            assert "the records were NOT checked" in done.stderr
    assert (data_dir / DB_NAME).read_bytes() == before
    assert main(["signoff", "verify", "--data-dir", str(data_dir)]) == 0  # space again: fine


def test_a_full_disk_is_named_as_such(data_dir, monkeypatch, capsys):
    def full(*args, **kwargs):
        error = sqlite3.OperationalError("database or disk is full")
        error.sqlite_errorcode = sqlite3.SQLITE_FULL
        raise error

    class NoRoom:
        execute = staticmethod(full)

        def close(self) -> None:
            pass

    monkeypatch.setattr(sqlite3, "connect", lambda *a, **k: NoRoom())
    assert main(["signoff", "verify", "--data-dir", str(data_dir)]) == 1
    assert main(["store", "info", "--data-dir", str(data_dir)]) != 0
    err = capsys.readouterr().err
    assert err.count("the disk is full (or the account's disk quota is used up)") == 2, err
    assert "not a readable" not in err and "or restore it from a backup" not in err
    assert "the records were NOT checked" in err


def test_list_and_verify_print_an_edited_record_s_escapes_written_out(data_dir, capsys):
    """A record edited in the database to hold terminal escapes (a title change, a clipboard
    write) is printed with them written out, never sent to the terminal (issue 37)."""
    sign(data_dir, "alice", "sensors")
    with sqlite3.connect(data_dir / DB_NAME) as conn:
        conn.execute(
            "UPDATE signoffs SET student = ?, note = ? WHERE id = 1",
            ("alice\x1b]0;PWNED\x07", "ok\x1b]52;c;aGk=\x07\x9b2J"),
        )
    assert main(["signoff", "list", "--data-dir", str(data_dir)]) == 0
    assert main(["signoff", "verify", "--data-dir", str(data_dir)]) == 1
    out = capsys.readouterr().out
    assert "alice\\x1b]0;PWNED\\x07" in out and "FAIL #1" in out
    assert not any(c in out for c in "\x1b\x07\x9b")


def test_a_program_name_that_begins_like_a_formula_is_never_a_formula_in_the_gradebook(
    data_dir, tmp_path
):
    name = '=HYPERLINK("http://x","y").viple'  # a name the student chose for their file
    run = {"run": 1, "program_sha256": "ab" * 32, "program_name": name,
           "metrics": {"exit_time": 12.0, "distance": 3.0}}  # fmt: skip
    fields = RecordFields(
        student="erin", partner="", driver="erin", lab="web-simulator", exercise="sensors",
        evidence=Evidence("", "", {"objectives": [{"kind": "exit", "passed": True,
                                                   "evidence": run}]}),
        objectives_passed=True,
    )  # fmt: skip
    with Store.open(data_dir) as store:
        sign_off(store, "Dr Chen", PASS, fields)
    target = tmp_path / "grades.csv"
    assert main(["signoff", "export", "--csv", str(target), "--data-dir", str(data_dir)]) == 0
    (row,) = list(csv.DictReader(target.open()))
    assert row["program"] == "'" + name  # shown as text by a spreadsheet, not run
    assert row["program_sha256"] == "sha256:" + "ab" * 32
