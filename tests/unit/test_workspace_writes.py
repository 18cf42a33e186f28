"""One write rule and one quota for every writer of a served student's workspace (issue 37):
the app's saves keep the file server's limits, counted from the disk at each save, and
nothing writes inside ~/runs but the run recorder."""

from __future__ import annotations

from pathlib import Path

import pytest

from workbench.door.appproc import AppSpec
from workbench.files.workspace import FileAccess, NoRoom, OutsideWorkspace
from workbench.files.workspace_files import UploadLimits, WorkspaceError, WorkspaceFiles
from workbench.wire.settings import AppSettings


def test_the_server_hands_its_upload_limits_to_each_session_s_app(tmp_path):
    limits = UploadLimits(file_size=4_000, quota_bytes=1_000_000, quota_files=20)
    spec = AppSpec("ana", "student", 1, 2, "", tmp_path, tmp_path / "r", tmp_path / "w")
    spec = AppSpec(**{**spec.__dict__, "uploads": limits})
    settings = AppSettings.from_json(spec.settings().to_json())  # as the app process reads it
    assert settings.uploads == limits
    assert AppSettings().uploads is None  # on a person's own machine: no quota


def test_app_saves_count_what_the_file_server_uploaded_meanwhile(tmp_path):
    access = FileAccess.confined_to(tmp_path / "ws", UploadLimits(0, 0, 3))
    root = access.workspace
    assert root is not None
    access.write_bytes("a.txt", b"one")
    (root / "b.txt").write_bytes(b"uploaded by sftp")  # another process, after the app began
    access.write_bytes("c.txt", b"three")
    with pytest.raises(NoRoom, match="at most 3 files and folders"):
        access.write_bytes("d.txt", b"four")
    access.write_bytes("a.txt", b"saved over")  # replacing a file takes no new slot
    assert not (root / "d.txt").exists() and (root / "a.txt").read_bytes() == b"saved over"


def test_the_file_cap_and_the_bytes_quota_hold_for_app_saves(tmp_path):
    access = FileAccess.confined_to(tmp_path / "ws", UploadLimits(100, 150, 0))
    with pytest.raises(NoRoom, match=r"~/big\.txt: a file may be at most 100 bytes"):
        access.write_bytes("big.txt", b"x" * 101)
    access.write_bytes("a.txt", b"x" * 100)
    with pytest.raises(NoRoom, match="at most 150 bytes on this server and take 100 bytes"):
        access.write_bytes("b.txt", b"x" * 60)
    access.write_bytes("a.txt", b"x" * 90)  # shrinking a file is always fine


def test_an_app_s_quota_leaves_the_file_server_s_uploads_alone(tmp_path):
    root = tmp_path / "ws"
    files = WorkspaceFiles(root)
    upload = files.begin_write(("up.bin",))
    upload.write(0, b"half")
    FileAccess.confined_to(root, UploadLimits())  # the app starting meanwhile
    upload.commit()
    assert (root / "up.bin").read_bytes() == b"half"


@pytest.mark.parametrize("typed", ["~/runs", "runs/x/run-001.jsonl", "~/runs/new.txt"])
def test_nothing_in_runs_is_written_by_the_app(tmp_path: Path, typed):
    access = FileAccess.confined_to(tmp_path / "ws")
    with pytest.raises(OutsideWorkspace, match="run records"):
        access.for_writing(typed)
    files = WorkspaceFiles(tmp_path / "ws")  # the file server: the same rule
    with pytest.raises(WorkspaceError, match="run records"):
        files.begin_write(tuple(typed.removeprefix("~/").split("/")))
