"""Replaying run records: stepping, jumping, playing on simulated time, bad records."""

import json

import pytest

from workbench.control.station import LabStation
from workbench.sim.mazefile import parse_maze, write_maze
from workbench.sim.record import FORMAT, RecordError, RunRecord
from workbench.sim.replay import SPEEDS, Replay, load_replay, replay_maze

BEND = parse_maze("#######\n#S....#\n#####.#\n#E....#\n#######\n", source="bend.txt")


def write_record(path, ticks, summary=True, header=None):
    lines = [header or {"type": "header", "format": FORMAT, "cell": 10.0}]
    lines += ticks
    if summary:
        lines.append({"type": "summary", "reached_exit": False})
    path.write_text("".join(json.dumps(obj) + "\n" for obj in lines))
    return path


def ticks(n, dt=0.05):
    out = []
    for i in range(n):
        tick = {"t": round(i * dt, 4), "pose": [15.0 + i, 15.0, 0.0], "sensors": {"1": 40.0 - i}}
        if i == 2:
            tick["state"] = "Forward"
        if i == 4:
            tick["state"] = "Turn"
            tick["events"] = ["collision"]
        out.append(tick)
    return out


@pytest.fixture
def simple(tmp_path):
    return load_replay(write_record(tmp_path / "r.jsonl", ticks(10)))


def test_frame_gives_the_recorded_tick(simple):
    f = simple.frame()
    assert (f.index, f.t, f.pose.x, f.sensors) == (0, 0.0, 15.0, {1: 40.0})
    assert f.block(simple.cell) == (1, 1) and f.state is None
    f = simple.frame(4)
    assert f.state == "Turn" and f.events == ("collision",)


def test_step_jump_and_ends(simple):
    assert simple.at_start and not simple.at_end
    assert simple.step() == 1 and simple.step(3) == 4
    assert simple.step(-2) == 2
    assert simple.step(-10) == 0
    assert simple.to_end() == 9 and simple.at_end
    assert simple.step() == 9
    assert simple.jump(5) == 5 and simple.time == pytest.approx(0.25)
    assert simple.to_start() == 0


def test_playing_runs_on_simulated_time_at_the_speed_factor(simple):
    simple.play()
    assert simple.advance(0.12) and simple.index == 2  # t = 0.12 -> tick at 0.10
    simple.speed = 2.0
    simple.advance(0.05)  # 0.1 s of the run later: t = 0.22
    assert simple.index == 4
    assert not simple.advance(0.001)  # less than a tick: same tick, time still moves
    simple.advance(10)
    assert simple.at_end and not simple.playing
    simple.play()  # from the end: starts over
    assert simple.index == 0 and simple.playing


def test_advance_does_nothing_while_paused(simple):
    assert not simple.advance(5) and simple.index == 0
    simple.toggle()
    assert simple.playing
    simple.step()
    assert not simple.playing  # stepping by hand pauses


def test_speed_steps_through_the_offered_factors(simple):
    assert simple.faster() == 2.0 and simple.slower() == 1.0
    for _ in range(20):
        simple.faster()
    assert simple.speed == SPEEDS[-1]
    for _ in range(20):
        simple.slower()
    assert simple.speed == SPEEDS[0]


def test_log_and_trail_up_to_the_current_tick(simple):
    assert simple.log() == [] and simple.trail() == [simple.poses[0]]
    simple.jump(4)
    assert simple.log() == [
        "   0.10s start in Forward",
        "   0.20s Forward -> Turn",
        "   0.20s collision",
    ]
    assert simple.log(1) == ["   0.20s collision"]
    assert len(simple.trail()) == 5


@pytest.mark.parametrize(
    ("bad", "reason"),
    [
        ({"pose": [1, 2, 3]}, '"t"'),
        ({"t": 0.1, "pose": [1, 2]}, "three numbers"),
        ({"t": 0.1, "pose": [1, 2, "x"]}, "three numbers"),
        ({"t": 0.1, "pose": [1, 2, 3], "sensors": []}, "port numbers"),
        ({"t": 0.1, "pose": [1, 2, 3], "sensors": {"a": 1}}, "port 'a'"),
        ({"t": 0.1, "pose": [1, 2, 3], "sensors": {"1": "far"}}, "'far' is not a number"),
        ({"t": 0.1, "pose": [1, 2, 3], "events": "exit"}, "list of event names"),
        ({"t": 0.1, "pose": [1, 2, 3], "state": 5}, "state name"),
        ({"t": 0.0, "pose": [1, 2, 3]}, "time goes backwards"),
    ],
)
def test_malformed_ticks_name_their_line(tmp_path, bad, reason):
    good = ticks(3)
    path = write_record(tmp_path / "bad.jsonl", [*good, bad])
    with pytest.raises(RecordError) as info:
        load_replay(path)
    assert str(info.value).startswith(f"{path}:5: ")
    assert reason in str(info.value)


def test_records_that_are_not_replayable(tmp_path):
    with pytest.raises(RecordError, match="no tick lines"):
        load_replay(write_record(tmp_path / "empty.jsonl", []))
    (tmp_path / "junk.jsonl").write_text("hello\n")
    with pytest.raises(RecordError, match=r"junk\.jsonl:1: not JSON"):
        load_replay(tmp_path / "junk.jsonl")
    with pytest.raises(RecordError, match="cannot read"):
        load_replay(tmp_path / "missing.jsonl")
    with pytest.raises(RecordError, match="tick 1"):
        Replay(RunRecord(header={}, ticks=[{"t": "x"}]))


def test_a_cut_off_record_replays_without_summary(tmp_path):
    replay = load_replay(write_record(tmp_path / "cut.jsonl", ticks(3), summary=False))
    assert replay.summary is None and len(replay) == 3


def station_record(tmp_path):
    b = LabStation.open(BEND, "erobotic", noise="off", record_dir=str(tmp_path))
    b.select_algorithm("right-wall")
    b.apply_algorithm_preset()
    b.start()
    for _ in range(100):
        b.step(60)
        if b.runs:
            break
    return b.runs[0].record


def test_a_real_run_replays_to_the_exit(tmp_path):
    replay = load_replay(station_record(tmp_path))
    assert replay.title == "right-wall on an unnamed maze"
    replay.to_end()
    assert replay.frame().block(replay.cell) == BEND.exits[0]
    assert replay.summary["reached_exit"] is True
    assert "exit" in replay.log()[-1]


def test_replay_maze_prefers_a_known_maze_then_the_file(tmp_path):
    path = station_record(tmp_path)
    replay = load_replay(path)
    assert replay_maze(replay, path, [BEND]) == (BEND, "")
    maze, note = replay_maze(replay, path)
    assert maze is None and "bend.txt is not found" in note
    write_maze(tmp_path / "bend.txt", BEND)
    maze, note = replay_maze(replay, path)  # found beside the record
    assert maze.same_layout(BEND) and note == ""
    write_maze(tmp_path / "bend.txt", BEND.with_block(3, 1, True))
    maze, note = replay_maze(replay, path)
    assert maze is not None and "has changed since this run" in note


def test_metrics_so_far_follow_the_recorded_poses(simple):
    m = simple.metrics()
    assert (m.distance, m.collisions, m.reached_exit) == (0.0, 0, False)
    simple.jump(4)
    m = simple.metrics()
    assert m.distance == pytest.approx(4.0) and m.distance_cells == pytest.approx(0.4)
    assert m.collisions == 1 and m.sim_time == pytest.approx(0.2)


def test_touches_are_counted_apart_and_old_records_without_them_still_load(tmp_path):
    touched = ticks(8)
    touched[6]["events"] = ["touch"]
    replay = load_replay(write_record(tmp_path / "t.jsonl", touched))
    replay.to_end()
    assert (replay.metrics().collisions, replay.metrics().touches) == (1, 1)
    # a record from before touches were counted: no touch events, no "touches" in the summary
    old = load_replay(write_record(tmp_path / "o.jsonl", ticks(8)))
    old.to_end()
    assert (old.metrics().collisions, old.metrics().touches) == (1, 0)
    assert "touches" not in old.summary


def test_snapshot_carries_the_tick_for_the_maze_view(tmp_path):
    header = {"type": "header", "format": FORMAT, "cell": 10.0, "sensors": ["distance:1:front"]}
    replay = load_replay(write_record(tmp_path / "s.jsonl", ticks(3), header=header))
    snap = replay.snapshot(1)
    assert snap.pose.x == 16.0 and snap.block == (1, 1) and snap.readings == {1: 39.0}
    assert [str(s) for s in snap.sensors] == ["distance:1:front"] and str(snap.driver) == "keys"


def test_a_bad_sensor_in_the_header_is_reported(tmp_path):
    header = {"type": "header", "format": FORMAT, "sensors": ["distance:1:top"]}
    with pytest.raises(RecordError, match=r"s\.jsonl: header: sensor 'distance:1:top'"):
        load_replay(write_record(tmp_path / "s.jsonl", ticks(3), header=header))


def test_metrics_at_the_end_agree_with_the_summary(tmp_path):
    replay = load_replay(station_record(tmp_path))
    replay.to_end()
    m, summary = replay.metrics(), replay.summary
    assert m.reached_exit and m.exit_time == pytest.approx(summary["exit_time"], abs=0.06)
    assert m.distance == pytest.approx(summary["distance"], rel=0.05)
    assert m.turns == summary["turns"] and m.collisions == summary["collisions"]
    assert m.touches == summary["touches"]


def test_a_binary_file_is_not_a_record(tmp_path):
    path = tmp_path / "bin.jsonl"
    path.write_bytes(b"\xff\xfe\x00binary")
    with pytest.raises(RecordError, match=r"bin\.jsonl: not a text file"):
        load_replay(path)


def test_an_unusable_maze_source_is_explained(tmp_path):
    header = {"type": "header", "format": FORMAT, "maze": {"source": "bad\0name.txt"}}
    # a control character in a record's names: the record is refused, never shown raw
    with pytest.raises(RecordError, match=r"1: maze\.source holds a control character"):
        load_replay(write_record(tmp_path / "r.jsonl", ticks(2), header=header))
    header["maze"] = {"source": "gone.txt"}
    replay = load_replay(write_record(tmp_path / "r.jsonl", ticks(2), header=header))
    assert replay_maze(replay, tmp_path / "r.jsonl") == (
        None,
        "the run's maze file gone.txt is not found, so the maze cannot be drawn",
    )
    (tmp_path / "broken.txt").write_text("---\nname: [\n---\n#S#\n")
    header["maze"] = {"source": "broken.txt"}
    replay = load_replay(write_record(tmp_path / "r2.jsonl", ticks(2), header=header))
    maze, note = replay_maze(replay, tmp_path / "r2.jsonl")
    assert maze is None and note.startswith("the run's maze ") and "cannot be read" in note
    header["maze"] = {"name": "x"}
    replay = load_replay(write_record(tmp_path / "r3.jsonl", ticks(2), header=header))
    assert replay_maze(replay, tmp_path / "r3.jsonl")[1] == (
        "the record does not name a maze file, so the maze cannot be drawn"
    )
