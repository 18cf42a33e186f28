"""Run records within their limits: a cap per record, a quota per runs folder, a full disk and
a file in the way never end a run; the run goes on unrecorded, with a notice that says why."""

from __future__ import annotations

import io
import json

import pytest

from workbench.control.recording import (
    MOVED_ASIDE,
    QUOTA_FULL,
    RecordQuota,
    folder_usage,
)
from workbench.control.station import RECORDING, LabStation
from workbench.files.sizes import parse_size
from workbench.files.workspace import FileAccess
from workbench.sim.mazefile import parse_maze
from workbench.sim.record import CAPPED, DISK_FULL, Recorder, read_record
from workbench.sim.session import Session

ROOM = parse_maze("#######\n#.....#\n#..S..#\n#.....#\n#######\n", source="room.txt")


def driving(station: LabStation, seconds: float) -> None:
    """Keys drive the robot round in circles for ``seconds`` of simulated time."""
    station.key("a")
    station.step(round(seconds * 60))


def test_a_record_stops_at_its_cap_and_keeps_its_summary(tmp_path):
    path = tmp_path / "capped.jsonl"
    recorder = Recorder(path, cap=20_000)
    session = Session(ROOM, "erobotic", noise="off", recorder=recorder)
    session.record_header()
    session.run(max_time=60)  # about 1,200 lines of some 100 bytes: far past the cap
    session.record_summary(ended="stopped")
    recorder.close()
    assert recorder.stopped is not None and recorder.stopped.reason == CAPPED
    assert path.stat().st_size <= 20_000
    record = read_record(path)
    assert record.summary is not None
    assert record.summary["sim_time"] == pytest.approx(60, abs=0.1)  # the run went on
    capped = record.summary["record_capped"]
    assert capped["bytes"] == 20_000
    assert capped["t"] == pytest.approx(record.ticks[-1]["t"])
    assert 0 < record.ticks[-1]["t"] < 30


def test_a_full_disk_cuts_the_record_back_to_whole_lines(tmp_path, disk):
    path = tmp_path / "full.jsonl"
    recorder = Recorder(path, keep_going=True)
    session = Session(ROOM, "erobotic", noise="off", recorder=recorder)
    session.record_header()
    session.run(max_time=2)
    disk.full = True
    session.run(max_time=4)  # the run goes on while no line can be written
    session.record_summary(ended="stopped")
    recorder.close()
    assert session.metrics().sim_time == pytest.approx(4, abs=0.05)
    assert recorder.stopped is not None and recorder.stopped.reason == DISK_FULL
    assert "space" in recorder.stopped.detail.lower()
    record = read_record(path)  # every line on disk is whole: it reads as a cut-off run
    assert record.summary is None
    assert record.ticks[-1]["t"] == pytest.approx(recorder.stopped.t)
    assert 1.5 < recorder.stopped.t <= 2.0


def test_without_keep_going_a_failed_write_still_raises(tmp_path, disk):
    recorder = Recorder(tmp_path / "r.jsonl")
    disk.full = True
    recorder.header(maze="m")
    with pytest.raises(OSError, match="space"):
        recorder.close()


def test_a_stream_record_is_written_line_by_line():
    buf = io.StringIO()
    recorder = Recorder(buf)
    recorder.header(maze="m")
    assert json.loads(buf.getvalue())["maze"] == "m"


def test_sizes_read_as_people_write_them():
    assert parse_size("20M") == 20_000_000
    assert parse_size("500k") == 500_000
    assert parse_size("1.5G") == 1_500_000_000
    assert parse_size("4096") == 4096
    with pytest.raises(ValueError, match=r"e\.g\. 20M"):
        parse_size("lots")


def test_the_station_goes_on_unrecorded_on_a_full_disk_and_records_again(tmp_path, disk):
    station = LabStation.open(ROOM, "erobotic", noise="off", record_dir=str(tmp_path / "runs"))
    driving(station, 1)
    disk.full = True
    driving(station, 2)
    notice = station.notice
    assert notice is not None and notice.kind == RECORDING
    assert notice.recording is not None and notice.recording.kind == DISK_FULL
    assert notice.recording.path.endswith("run-001.jsonl")
    before = station.snapshot().time
    driving(station, 1)  # the run goes on
    assert station.snapshot().time == pytest.approx(before + 1, abs=0.05)
    disk.full = False
    station.reset_robot()
    driving(station, 1)
    station.reset_robot()
    first, second = station.runs
    assert read_record(first.record).summary is None  # cut off where the disk filled
    again = read_record(second.record)
    assert second.record.endswith("run-002.jsonl")
    assert again.summary is not None and again.summary["ended"] == "reset"


def test_the_station_stops_a_record_at_its_cap_and_says_so(tmp_path):
    quota = RecordQuota(record=30_000, runs=None)
    station = LabStation.open(
        ROOM, "erobotic", noise="off", record_dir=str(tmp_path), record_quota=quota
    )
    driving(station, 60)
    notice = station.notice
    assert notice is not None and notice.recording is not None
    assert notice.recording.kind == CAPPED and notice.recording.detail == "30000"
    assert station.snapshot().time == pytest.approx(60, abs=0.05)
    station.reset_robot()
    record = read_record(station.runs[0].record)
    assert record.summary is not None and record.summary["record_capped"]["bytes"] == 30_000


def test_a_spent_quota_leaves_runs_unrecorded(tmp_path):
    runs = tmp_path / "runs"
    (runs / "old").mkdir(parents=True)
    (runs / "old" / "run-001.jsonl").write_bytes(b"x" * 190_000)
    quota = RecordQuota(record=None, runs=200_000, folder=str(runs))
    station = LabStation.open(
        ROOM, "erobotic", noise="off", record_dir=str(runs / "new"), record_quota=quota
    )
    driving(station, 2)
    notice = station.notice
    assert notice is not None and notice.recording is not None
    assert notice.recording.kind == QUOTA_FULL and notice.recording.path == str(runs)
    station.reset_robot()
    assert station.runs[0].record is None
    assert station.runs[0].metrics.sim_time == pytest.approx(2, abs=0.05)
    assert not list((runs / "new").glob("*.jsonl"))


def test_a_record_may_take_only_what_is_left_of_the_quota(tmp_path):
    runs = tmp_path / "runs"
    (runs / "old").mkdir(parents=True)
    (runs / "old" / "run-001.jsonl").write_bytes(b"x" * 100_000)
    quota = RecordQuota(record=None, runs=200_000, folder=str(runs))
    station = LabStation.open(
        ROOM, "erobotic", noise="off", record_dir=str(runs / "new"), record_quota=quota
    )
    driving(station, 120)
    station.reset_robot()
    assert 190_000 < folder_usage(runs) <= 200_000
    assert station.notice is not None and station.notice.recording.kind == CAPPED
    assert read_record(station.runs[0].record).summary["record_capped"]["bytes"] == 100_000


def test_a_file_named_runs_is_moved_aside_and_the_run_recorded(tmp_path):
    workspace = tmp_path / "ws"
    files = FileAccess.confined_to(workspace)
    (workspace / "runs").write_text("a maze saved as ~/runs\n")
    station = LabStation.open(
        ROOM,
        "erobotic",
        noise="off",
        record_dir=str(workspace / "runs" / "20250101-120000"),
        record_quota=RecordQuota(folder=str(workspace / "runs")),
        files=files,
    )
    assert station.key("w")  # no NotADirectoryError
    notice = station.notice
    assert notice is not None and notice.recording is not None
    assert notice.recording.kind == MOVED_ASIDE
    assert files.shown(notice.recording.detail) == "~/runs.taken-1"
    assert (workspace / "runs.taken-1").read_text() == "a maze saved as ~/runs\n"
    station.step(60)
    station.reset_robot()
    assert read_record(station.runs[0].record).summary is not None


def test_outside_a_workspace_a_file_in_the_way_is_left_alone(tmp_path):
    (tmp_path / "runs").write_text("mine\n")
    station = LabStation.open(
        ROOM, "erobotic", noise="off", record_dir=str(tmp_path / "runs" / "today")
    )
    driving(station, 1)
    assert station.notice is not None and station.notice.recording.kind == "no folder"
    assert (tmp_path / "runs").read_text() == "mine\n"
    assert station.snapshot().time == pytest.approx(1, abs=0.05)


def test_serve_ssh_hands_its_record_caps_to_every_session_s_app(tmp_path):
    from workbench.cli import build_parser
    from workbench.control.recording import RecordQuota
    from workbench.door.appproc import AppSpec
    from workbench.wire.settings import AppSettings

    parser = build_parser()
    args = parser.parse_args(["serve-ssh", "--record-cap", "5M", "--runs-quota", "0"])
    assert (args.record_cap, args.runs_quota) == (5_000_000, None)
    spec = AppSpec(
        "ann", "student", 5000, 5001, "", tmp_path / "data", tmp_path / "ws" / "runs" / "r1",
        tmp_path / "ws", record_quota=RecordQuota(args.record_cap, args.runs_quota),
    )  # fmt: skip
    # what the session's app reads back from the JSON it is given
    quota = AppSettings.from_json(spec.settings().to_json()).record_quota
    assert quota == RecordQuota(5_000_000, None, str(tmp_path / "ws" / "runs"))
    assert parser.parse_args([]).record_cap == 20_000_000
