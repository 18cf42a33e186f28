"""The data folder holds students' progress and login addresses: it and everything the
workbench makes in it are the account's alone, whatever the umask; a folder found open to
others is tightened with a notice; an empty database file is refused, not silently replaced."""

from __future__ import annotations

import os
import stat
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path

import pytest

from workbench.labs.lastpair import save_last_pair
from workbench.labs.store.pending import PendingWrite, pending_path, save_pending
from workbench.labs.store.store import DB_NAME, Store, StoreError, read_signoffs

ROOT = Path(__file__).resolve().parents[2]


def mode(path: Path) -> int:
    return stat.S_IMODE(path.stat().st_mode)


@pytest.fixture
def open_umask() -> Iterator[None]:
    """The usual umask that makes files readable by everyone (0644) and folders 0755."""
    old = os.umask(0o022)
    try:
        yield
    finally:
        os.umask(old)


def test_what_the_workbench_makes_in_the_data_folder_is_private(tmp_path, open_umask):
    data = tmp_path / "data"
    with Store.open(data) as store:
        store.progress.save("ana", "lab", "ex", {"n": 1})
        companions = [data / f"{DB_NAME}-wal", data / f"{DB_NAME}-shm"]
        assert all(p.exists() for p in companions)
        assert [mode(p) for p in companions] == [0o600, 0o600]
    assert mode(data) == 0o700 and mode(data / DB_NAME) == 0o600
    kept = pending_path(data, "ana")
    save_pending(kept, "ana", [PendingWrite("place", ("ana", "lab", "ex", "2026-01-01T00:00:00Z"))])
    assert mode(kept.parent) == 0o700 and mode(kept) == 0o600
    save_last_pair(data, "ana", "ben")
    assert mode(data / "last-pair.json") == 0o600
    assert sorted(p.name for p in data.iterdir()) == ["last-pair.json", "pending", DB_NAME]


def test_a_data_folder_open_to_others_is_made_private_with_a_notice(tmp_path, open_umask):
    data = tmp_path / "data"
    Store.open(data).close()
    data.chmod(0o755)
    (data / DB_NAME).chmod(0o644)
    with Store.open(data) as store:
        notices = store.notices
    assert mode(data) == 0o700 and mode(data / DB_NAME) == 0o600
    assert len(notices) == 2
    assert notices[0] == f"{data}: was open to other accounts (mode 0755); made private (0700)"
    assert notices[1].startswith(f"{data / DB_NAME}: was open to other accounts (mode 0644)")
    with Store.open(data) as store:
        assert store.notices == []  # once private, nothing more to say


def test_an_empty_database_file_is_refused_and_left_as_it_is(tmp_path):
    data = tmp_path / "data"
    data.mkdir()
    (data / DB_NAME).touch()
    for opening in (lambda: Store.open(data), lambda: read_signoffs(data)):
        with pytest.raises(StoreError) as caught:
            opening()
        text = str(caught.value)
        assert text.startswith(f"{data / DB_NAME}: an empty file (0 bytes), not a workbench")
        assert "move the file aside to start a new one" in text
    assert (data / DB_NAME).stat().st_size == 0
    assert sorted(p.name for p in data.iterdir()) == [DB_NAME]


def test_the_database_the_workbench_makes_is_never_an_empty_file(tmp_path):
    """A new store is built aside and linked into place: a second app opening the folder at
    that moment finds either no file or a whole database, never one of 0 bytes."""
    data = tmp_path / "data"
    with Store.open(data):
        assert (data / DB_NAME).stat().st_size > 0
    with Store.open(data) as again:
        assert again.schema_version() >= 2
    assert sorted(p.name for p in data.iterdir()) == [DB_NAME]


LOGGING = """
import logging, os, sys
from pathlib import Path
from workbench.door.serverlog import setup_logging
os.umask(0o022)
setup_logging(Path(sys.argv[1]), stream=False)
logging.getLogger("workbench.ssh.server").info("a line")
(Path(sys.argv[1]) / "logs" / "ana").mkdir(parents=True, exist_ok=True)
(Path(sys.argv[1]) / "logs" / "ana" / "session.log").write_text("an app's errors")
"""


def test_the_lab_server_keeps_its_logs_private_and_tightens_what_it_finds(tmp_path):
    data = tmp_path / "served"
    (data / "logs" / "bob").mkdir(parents=True)
    (data / "logs" / "bob" / "old.log").write_text("from before")
    for path, wide in ((data, 0o755), (data / "logs", 0o755), (data / "logs" / "bob", 0o755)):
        path.chmod(wide)
    (data / "logs" / "bob" / "old.log").chmod(0o644)
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    done = subprocess.run(
        [sys.executable, "-c", LOGGING, str(data)], env=env, capture_output=True, timeout=60
    )
    assert done.returncode == 0, done.stderr
    assert mode(data) == 0o700 and mode(data / "ssh.log") == 0o600
    for folder in (data / "logs", data / "logs" / "bob", data / "logs" / "ana"):
        assert mode(folder) == 0o700, folder
    for log in (data / "logs" / "bob" / "old.log", data / "logs" / "ana" / "session.log"):
        assert mode(log) == 0o600, log
    text = (data / "ssh.log").read_text()
    assert "made private to this account: 4 file(s) and folder(s)" in text
