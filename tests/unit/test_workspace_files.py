"""The workspace as a file server sees it: names checked, links never followed, the run
records read-only, uploads whole or not at all, and one quota count for racing uploads."""

from __future__ import annotations

import os
import re

import pytest

from workbench.files.names import BadPath, path_parts, resolved_parts
from workbench.files.workspace_files import (
    Refusal,
    UploadLimits,
    WorkspaceError,
    WorkspaceFiles,
)


def refused(call, *args, **kwargs) -> WorkspaceError:
    with pytest.raises(WorkspaceError) as caught:
        call(*args, **kwargs)
    return caught.value


def test_a_path_is_its_parts_inside_the_workspace_and_bad_parts_say_why():
    assert path_parts(b"/") == () and path_parts(b"") == ()
    assert path_parts(b"//a/./b/") == ("a", "b")
    assert resolved_parts(b"/a/b/../../../c") == ("c",)
    for bad, why in [
        (b"a/../b", "'..'"),
        (b"tab\there", "U+0009"),
        (b"del\x7f", "U+007F"),
        ("c1\u0085".encode(), "U+0085"),
        ("ltr\u200e".encode(), "bidi control character (U+200E"),
        (b"x" * 256, "at most 255 bytes"),
        (b"a/" * 600, "at most 1024 bytes"),
        (b"\xc3(", "UTF-8"),
        (b".uploading", "keeps uploads"),
    ]:
        with pytest.raises(BadPath, match=re.escape(why)):
            path_parts(bad)
    assert path_parts("é" * 127) == ("é" * 127,)  # 254 bytes: within a name's 255


def test_an_upload_is_seen_only_once_committed_and_tells_the_hook(tmp_path):
    changed: list[str] = []
    files = WorkspaceFiles(tmp_path / "ws", on_change=changed.append)
    files.mkdir(("progs",))
    upload = files.begin_write(("progs", "p.viple"))
    upload.write(0, b"hello ")
    upload.write(6, b"world")
    assert not (tmp_path / "ws" / "progs" / "p.viple").exists()
    assert upload.read(0, 5) == b"hello"
    upload.commit()
    assert (tmp_path / "ws" / "progs" / "p.viple").read_bytes() == b"hello world"
    files.rename(("progs", "p.viple"), ("p.viple",))
    files.remove(("p.viple",))
    assert changed == ["progs", "progs/p.viple", "progs/p.viple", "p.viple", "p.viple"]
    assert (files.usage.bytes, files.usage.files) == (0, 1)


def test_an_abandoned_upload_leaves_nothing_and_frees_its_room(tmp_path):
    files = WorkspaceFiles(tmp_path, UploadLimits(quota_bytes=100, quota_files=5))
    upload = files.begin_write(("a",))
    upload.write(0, b"x" * 90)
    other = files.begin_write(("b",))
    assert refused(other.write, 0, b"y" * 20).kind is Refusal.QUOTA
    upload.abandon()
    other.abandon()
    assert list(tmp_path.iterdir()) == [tmp_path / ".uploading"]
    assert list((tmp_path / ".uploading").iterdir()) == []
    assert (files.usage.reserved_bytes, files.usage.reserved_files) == (0, 0)
    again = files.begin_write(("b",))
    again.write(0, b"z" * 100)  # the whole quota is there again
    again.commit()
    assert (files.usage.bytes, files.usage.files) == (100, 1)


def test_racing_uploads_share_one_count_and_the_file_cap_holds_during_the_write(tmp_path):
    files = WorkspaceFiles(tmp_path, UploadLimits(file_size=60, quota_bytes=100, quota_files=5))
    one, two = files.begin_write(("one",)), files.begin_write(("two",))
    one.write(0, b"1" * 50)
    two.write(0, b"2" * 40)
    error = refused(two.write, 40, b"2" * 20)
    assert error.kind is Refusal.QUOTA and "at most 100 bytes" in error.message
    error = refused(one.write, 50, b"1" * 11)
    assert error.kind is Refusal.TOO_BIG and "a file may be at most 60 bytes" in error.message
    one.commit()
    two.abandon()
    assert (files.usage.bytes, files.usage.reserved_bytes, files.usage.reserved_files) == (
        50, 0, 0
    )  # fmt: skip


def test_the_count_starts_from_the_disk_without_the_run_records(tmp_path):
    (tmp_path / "runs" / "1").mkdir(parents=True)
    (tmp_path / "runs" / "1" / "run-001.jsonl").write_bytes(b"r" * 1000)
    (tmp_path / "maze.txt").write_bytes(b"m" * 30)
    (tmp_path / ".uploading").mkdir()
    (tmp_path / ".uploading" / ".upload.x.tmp").write_bytes(b"left by a stopped server")
    files = WorkspaceFiles(tmp_path)
    assert (files.usage.bytes, files.usage.files) == (30, 1)
    assert not (tmp_path / ".uploading").exists()


def test_the_run_records_are_read_and_never_changed(tmp_path):
    (tmp_path / "runs" / "1").mkdir(parents=True)
    (tmp_path / "runs" / "1" / "run-001.jsonl").write_text("{}\n")
    files = WorkspaceFiles(tmp_path)
    assert [e.name for e in files.list(("runs", "1"))] == ["run-001.jsonl"]
    with files.open_read(("runs", "1", "run-001.jsonl")) as fh:
        assert fh.read() == b"{}\n"
    for call, args in [
        (files.begin_write, (("runs", "1", "x"),)),
        (files.remove, (("runs", "1", "run-001.jsonl"),)),
        (files.rename, (("runs",), ("mine",))),
        (files.rename, (("runs", "1"), ("old",))),
        (files.mkdir, (("runs", "2"),)),
    ]:
        assert "/runs holds the run records" in refused(call, *args).message


def test_links_found_in_a_workspace_are_never_followed(tmp_path):
    outside = tmp_path / "secret"
    outside.mkdir()
    (outside / "key").write_text("private")
    ws = tmp_path / "ws"
    ws.mkdir()
    os.symlink(outside, ws / "door")
    os.symlink(outside / "key", ws / "key.txt")
    os.mkfifo(ws / "pipe")
    files = WorkspaceFiles(ws)
    assert files.list(()) == []  # links and special files are not shown
    for parts in [("door", "key"), ("key.txt",), ("door",)]:
        assert refused(files.open_read, parts).kind is Refusal.DENIED
        assert refused(files.begin_write, parts).kind in (Refusal.DENIED, Refusal.IS_A_FOLDER)
    assert refused(files.open_read, ("pipe",)).kind is Refusal.DENIED
    assert (outside / "key").read_text() == "private"


def test_a_read_only_view_changes_nothing(tmp_path):
    (tmp_path / "ann").mkdir()
    (tmp_path / "ann" / "p.viple").write_text("x")
    files = WorkspaceFiles(tmp_path, read_only=True, protected=())
    assert [e.name for e in files.list(())] == ["ann"]
    for call, args in [
        (files.begin_write, (("ann", "q"),)),
        (files.remove, (("ann", "p.viple"),)),
        (files.mkdir, (("ben",),)),
        (files.rename, (("ann",), ("ben",))),
    ]:
        assert "read-only for you" in refused(call, *args).message
    assert (tmp_path / "ann" / "p.viple").read_text() == "x"
