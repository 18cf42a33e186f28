"""A course's store on PostgreSQL from the command line: `store migrate`, and `signoff`,
`instructor` and `store info` given `--db` or `$WORKBENCH_DB`."""

from __future__ import annotations

import io
import sys
from datetime import UTC, datetime
from pathlib import Path

import pytest

from workbench.cli import main
from workbench.labs.signoff.instructors import create_instructor
from workbench.labs.signoff.roster import load_roster
from workbench.labs.signoff.signing import sign_off
from workbench.labs.signoff.signoff_errors import WrongPassphrase
from workbench.labs.signoff.signoff_record import RecordFields
from workbench.labs.store.store import Store

from .signoff_support import FAST, PASS, head_of, sign


@pytest.fixture
def section(tmp_path, config_dir) -> Path:
    """A lab machine's data folder after a week of labs: an instructor, three sign-offs, a
    wrong passphrase, progress, places and drivers."""
    d = tmp_path / "data"
    create_instructor(d, "Dr Chen", PASS, kdf=FAST, trusted=config_dir / "roster.json")
    for n, student in enumerate(("ana", "ben", "cy")):
        sign(d, student, f"ex{n}", when=n)
    with Store.open(d) as store:
        store.progress.save("ana", "web", "ex1", {"answers": {"q1": "3"}})
        store.progress.set_place("ana", "web", "ex1")
        store.progress.set_driver("ana", "", "web", "ex2", "ana")
        fields = RecordFields(student="ana", lab="web", exercise="ex1", objectives_passed=True)
        with pytest.raises(WrongPassphrase):
            sign_off(store, "Dr Chen", "not the passphrase", fields)
    return d


def test_migrate_copies_a_data_folder_and_checks_the_copy(section, pg_url, capsys):
    assert main(["signoff", "verify", "--data-dir", str(section)]) == 0
    head = head_of(capsys.readouterr().out)

    assert main(["store", "migrate", "--to", pg_url, "--data-dir", str(section)]) == 0
    out = capsys.readouterr().out
    assert f"sign-off log head {head}, the same in both" in out
    for line in ("signoffs     3 row(s)", "progress     1 row(s)", "events       1 row(s)"):
        assert line in out
    assert "instructors  1 row(s)" in out

    # the whole course's log, checked from the database alone, with the head kept before
    assert main(["signoff", "verify", "--db", pg_url, "--head", head]) == 0
    assert f"head {head}" in capsys.readouterr().out

    # a student resumes on any server: progress, place and driver came along
    elsewhere = section.parent / "server-two"
    with Store.open(elsewhere, db=pg_url) as store:
        assert store.progress.of("ana") == {("web", "ex1"): {"answers": {"q1": "3"}}}
        assert store.progress.place("ana") == ("web", "ex1")
        assert store.progress.drivers("ana") == {("web", "ex2"): "ana"}
        # the instructor's key came along: signing goes on from the copied head
        _, record = sign_off(
            store,
            "Dr Chen",
            PASS,
            RecordFields(student="dee", lab="web", exercise="ex4", objectives_passed=True),
        )
        assert store.signoffs.lockout("Dr Chen").failures == 0
    assert record.seq == 4
    assert main(["signoff", "verify", "--db", pg_url, "--head", head]) == 0
    assert "all 4 record(s) verify" in capsys.readouterr().out

    # the SQLite store is left as it was, and a second copy into the same database is refused
    assert main(["signoff", "verify", "--data-dir", str(section), "--head", head]) == 0
    capsys.readouterr()
    assert main(["store", "migrate", "--to", pg_url, "--data-dir", str(section)]) == 1
    err = capsys.readouterr().err
    assert "already holds 4 signoffs" in err and "empty database" in err


def test_migrate_needs_a_store_to_copy_and_a_postgresql_url(tmp_path, pg_url, capsys):
    assert main(["store", "migrate", "--to", pg_url, "--data-dir", str(tmp_path / "none")]) == 1
    assert "no workbench database here" in capsys.readouterr().err
    assert main(["store", "migrate", "--to", "mysql://db/course"]) == 2
    err = capsys.readouterr().err
    assert "--to: 'mysql://db/course' is not a PostgreSQL URL" in err


def test_instructors_and_sign_offs_on_a_course_database_from_the_environment(
    tmp_path, pg_url, monkeypatch, capsys, config_dir
):
    monkeypatch.setenv("WORKBENCH_DB", pg_url)
    monkeypatch.setattr(sys, "stdin", io.StringIO(PASS + "\n"))
    data = tmp_path / "data"
    assert main(["instructor", "add", "Dr Lee", "--passphrase-stdin", "--data-dir", str(data)]) == 0
    out = capsys.readouterr().out
    assert "encrypted in the course database postgresql://postgres@127.0.0.1" in out
    assert not (data / "roster.json").exists()
    assert "Dr Lee" in load_roster(config_dir / "roster.json")  # the trusted copy
    assert main(["instructor", "list"]) == 0
    listed = capsys.readouterr().out
    assert "Dr Lee" in listed and "key here" in listed and "trusted" in listed

    with Store.open(tmp_path / "other", db=pg_url) as store:
        moment = datetime(2026, 3, 2, 10, tzinfo=UTC)
        fields = RecordFields(student="ana", lab="web", exercise="ex1", objectives_passed=True)
        sign_off(store, "Dr Lee", PASS, fields, clock=lambda: moment)
    assert main(["signoff", "list"]) == 0
    assert "#1  2026-03-02T10:00:00Z  ana  web/ex1  by Dr Lee" in capsys.readouterr().out
    csv_path = tmp_path / "grades.csv"
    assert main(["signoff", "export", "--csv", str(csv_path)]) == 0
    assert "ana" in csv_path.read_text()
    assert main(["store", "info"]) == 0
    info = capsys.readouterr().out
    assert "PostgreSQL" in info and "3 instructors' roster" in info and "signoffs 1" in info


def test_a_bad_database_url_is_refused_with_what_to_write(capsys, monkeypatch):
    assert main(["signoff", "verify", "--db", "sqlite:///tmp/x.db"]) == 2
    err = capsys.readouterr().err
    assert "not a PostgreSQL URL" in err and "postgresql://USER" in err
    monkeypatch.setenv("WORKBENCH_DB", "redis://cache")
    assert main(["signoff", "list"]) == 2
    assert "$WORKBENCH_DB: 'redis://cache' is not a PostgreSQL URL" in capsys.readouterr().err


def test_db_may_be_given_before_the_command_too(capsys):
    assert main(["--db", "sqlite:///tmp/x.db", "signoff", "verify"]) == 2
    assert "not a PostgreSQL URL" in capsys.readouterr().err
