"""`workbench instructor add` for a second data folder (a lab server on the same account): the
same key goes there, and every later command works without --roster."""

from __future__ import annotations

import io
import sys
from pathlib import Path

import pytest

from workbench.cli import main
from workbench.labs.signoff.instructors import create_instructor, key_path, unlock_instructor
from workbench.labs.signoff.roster import load_roster, roster_path
from workbench.labs.store.store import Store

from .signoff_support import FAST, PASS, sign


@pytest.fixture(autouse=True)
def trusted(tmp_path, monkeypatch) -> Path:
    """The instructor's trusted roster, in their configuration folder."""
    monkeypatch.setenv("WORKBENCH_CONFIG", str(tmp_path / "config"))
    return tmp_path / "config" / "roster.json"


@pytest.fixture
def first(tmp_path, monkeypatch, trusted) -> Path:
    """The first data folder, where Dr Chen was added; the default one ($WORKBENCH_DATA)."""
    d = tmp_path / "first"
    create_instructor(d, "Dr Chen", PASS, kdf=FAST, trusted=trusted)
    monkeypatch.setenv("WORKBENCH_DATA", str(d))
    return d


def add(monkeypatch, *args: str, passphrase: str = PASS) -> int:
    monkeypatch.setattr(sys, "stdin", io.StringIO(passphrase + "\n"))
    return main(["instructor", "add", "Dr Chen", "--passphrase-stdin", *args])


def test_the_same_key_goes_to_a_second_data_folder(first, tmp_path, monkeypatch, capsys, trusted):
    second = tmp_path / "lab-server"
    before = trusted.read_text()
    assert add(monkeypatch, "--data-dir", str(second)) == 0
    out = capsys.readouterr().out
    fingerprint = load_roster(trusted)["Dr Chen"].fingerprint()
    assert f"added Dr Chen (key {fingerprint}) to {second}, the same key as in {first}" in out
    assert trusted.read_text() == before
    assert load_roster(roster_path(second)) == load_roster(trusted)
    assert key_path(second, "Dr Chen").read_text() == key_path(first, "Dr Chen").read_text()
    assert unlock_instructor(second, "Dr Chen", PASS).name == "Dr Chen"
    # signing on the second folder verifies with the one trusted roster, no --roster needed
    Store.open(second).close()
    sign(second, "alice", "sensors")
    assert main(["signoff", "verify", "--data-dir", str(second)]) == 0
    assert "all 1 record(s) verify" in capsys.readouterr().out
    assert main(["instructor", "list", "--data-dir", str(second)]) == 0
    assert "key here  trusted" in capsys.readouterr().out
    # once there, it is there
    assert add(monkeypatch, "--data-dir", str(second)) == 2
    assert "already in the roster" in capsys.readouterr().err


def test_the_folder_holding_the_key_can_be_named(first, tmp_path, monkeypatch, capsys):
    monkeypatch.delenv("WORKBENCH_DATA")
    second = tmp_path / "lab-server"
    assert add(monkeypatch, "--data-dir", str(second), "--key-from", str(first)) == 0
    assert "Dr Chen" in load_roster(roster_path(second))


def test_without_the_key_it_says_the_command_that_adds_it(first, tmp_path, monkeypatch, capsys):
    second = tmp_path / "lab server"
    empty = tmp_path / "empty"
    assert add(monkeypatch, "--data-dir", str(second), "--key-from", str(empty)) == 2
    err = capsys.readouterr().err
    assert f"{empty} holds no key for Dr Chen" in err
    assert f"workbench instructor add 'Dr Chen' --data-dir '{second}' --key-from DIR" in err
    assert not roster_path(second).exists()


def test_a_wrong_passphrase_copies_nothing(first, tmp_path, monkeypatch, capsys):
    second = tmp_path / "lab-server"
    assert add(monkeypatch, "--data-dir", str(second), passphrase="not the passphrase") == 2
    assert "wrong passphrase for Dr Chen" in capsys.readouterr().err
    assert not key_path(second, "Dr Chen").exists() and not roster_path(second).exists()


def test_a_key_that_is_not_the_trusted_one_is_not_copied(first, tmp_path, monkeypatch, capsys):
    other = tmp_path / "other"
    create_instructor(other, "Dr Chen", PASS, kdf=FAST)  # same name, another key
    second = tmp_path / "lab-server"
    assert add(monkeypatch, "--data-dir", str(second), "--key-from", str(other)) == 2
    assert "holds another key for Dr Chen than your trusted roster" in capsys.readouterr().err
    assert not key_path(second, "Dr Chen").exists()
