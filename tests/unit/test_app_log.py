"""A session app's error log as the lab server writes it: capped and rotated once, its last
lines kept in memory while the disk is full and written (with what was lost) once there is
room again, or handed to ssh.log at the session's end; a user's old logs removed for room."""

from __future__ import annotations

import os

from tests.full_disk import FakeDisk
from workbench.door.applog import KEPT, AppLog, make_room


def lines(first: int, count: int) -> bytes:
    return b"".join(
        f"line {n:06d} of the app's errors\n".encode() for n in range(first, first + count)
    )


def test_a_log_past_its_size_is_rotated_once_and_keeps_the_latest_output(tmp_path):
    log = AppLog(tmp_path / "s.log", 10_000)
    for n in range(0, 3000, 100):
        log.feed(lines(n, 100))
    log.close()
    assert log.path.stat().st_size <= 10_000 and log.rotated.stat().st_size <= 10_000
    assert sorted(p.name for p in tmp_path.iterdir()) == ["s.log", "s.log.1"]
    assert log.path.read_bytes().endswith(b"line 002999 of the app's errors\n")
    # the rotated log holds what came just before
    newest_first = log.path.read_bytes().split(b"\n")[0]
    assert log.rotated.read_bytes().endswith(
        f"line {int(newest_first.split()[1]) - 1:06d} of the app's errors\n".encode()
    )
    assert log.report() == []


def test_while_the_disk_is_full_the_last_lines_are_kept_and_written_with_a_note_later(tmp_path):
    disk = FakeDisk()
    log = AppLog(tmp_path / "s.log", 1_000_000, opener=disk.open, retry_every=0)
    log.feed(lines(0, 10))
    disk.full = True
    for n in range(10, 5010, 50):
        log.feed(lines(n, 50))  # far more than is kept in memory: nothing raised
    assert disk.refused > 0
    assert log.lost_lines > 0
    disk.full = False
    log.feed(b"after the disk had room again\n")
    log.close()
    text = log.path.read_text()
    assert text.startswith("line 000000")
    assert "line 000009 of the app's errors\n[lab server] " in text
    assert "of this app's error output were lost while its log could not be written " in text
    assert "(No space left on device)" in text
    assert text.endswith("line 005009 of the app's errors\nafter the disk had room again\n")
    assert len(text) < 1_000_000
    assert log.report() == []


def test_lines_never_written_go_to_the_server_log_at_the_end_shown_safely(tmp_path):
    disk = FakeDisk()
    log = AppLog(tmp_path / "s.log", 1_000_000, opener=disk.open, retry_every=3600)
    disk.full = True
    log.feed(lines(0, 5000))
    log.feed(b"Traceback: \x1b[2Jcleared your screen\n")
    log.close()
    report = log.report()
    assert "could not be written (No space left on device)" in report[0]
    assert "5001 lines of the app's error output not written" in report[0]
    assert report[-1] == "Traceback: ?[2Jcleared your screen"
    assert report[-2] == "line 004999 of the app's errors"
    assert len(report) == 21
    # memory held meanwhile stayed bounded
    assert len(log._unwritten) <= KEPT


def test_the_end_of_the_output_is_kept_in_memory_even_when_the_disk_is_full(tmp_path):
    disk = FakeDisk()
    disk.full = True
    log = AppLog(tmp_path / "s.log", 1_000, opener=disk.open)
    log.feed(lines(0, 100) + b"MemoryError\n")
    assert b"MemoryError" in log.tail


def test_a_users_oldest_logs_are_removed_until_there_is_room(tmp_path):
    for n, name in enumerate(["a.log", "b.log", "c.log", "d.log"]):
        path = tmp_path / name
        path.write_bytes(b"x" * 300_000)
        os.utime(path, (1_000_000 + n, 1_000_000 + n))
    busy = tmp_path / "a.log"  # still written by a running session
    removed, freed = make_room(tmp_path, 1_000_000, 200_000, {busy})
    assert (removed, freed) == (2, 600_000)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.log", "d.log"]
    assert make_room(tmp_path, 0, 200_000) == (0, 0)
