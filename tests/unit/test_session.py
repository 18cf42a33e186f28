"""The session: commands in, metrics, snapshots and run records out."""

import io
import json

import pytest

from workbench.sim.commands import MoveAtPower, TurnByDegrees, WheelPowers
from workbench.sim.driver import Driver
from workbench.sim.mazefile import parse_maze
from workbench.sim.metrics import TurnCounter
from workbench.sim.record import FORMAT, Recorder, RecordError, read_record
from workbench.sim.session import Session

CORRIDOR = parse_maze("##########\n#S......E#\n##########\n", source="corridor.txt")
ROOM = parse_maze("#######\n#.....#\n#..S..#\n#.....#\n#######\n", source="room.txt")


def test_driving_to_the_exit_gives_the_course_metrics():
    session = Session(CORRIDOR, "erobotic", noise="off")
    session.command(MoveAtPower(1.0), driver=Driver.program("a script"))
    metrics = session.run(max_time=30)
    assert metrics.reached_exit
    # the exit block's edge is 6.5 blocks from the start block's centre
    assert metrics.distance_cells == pytest.approx(6.5, abs=0.05)
    assert metrics.turn_degrees == pytest.approx(0, abs=0.01)
    assert metrics.turns == 0 and metrics.collisions == 0
    assert metrics.efficiency == pytest.approx(1.0, abs=0.01)
    assert metrics.exit_time == metrics.sim_time
    assert session.snapshot().driver == Driver.program("a script")


def test_run_without_exits_goes_to_the_time_limit():
    session = Session(ROOM, "erobotic", noise="off")
    metrics = session.run(max_time=2.0)
    assert not metrics.reached_exit and metrics.sim_time == pytest.approx(2.0)
    assert metrics.efficiency is None


def test_turns_count_rotations_not_corrections():
    session = Session(ROOM, "unity", noise="off")
    for degrees in (90, -90, 1, -1, 180):
        session.command(TurnByDegrees(degrees))
        session.run(max_time=session.world.time + 8)
    metrics = session.metrics()
    assert metrics.turns == 3
    assert metrics.turn_degrees == pytest.approx(362, abs=1)


def test_turn_counter_counts_each_sweep_once():
    counter = TurnCounter()
    for _ in range(20):
        counter.update(5.0, 0.05)  # 100 deg/s for a second: one 100-degree turn
    counter.update(0.0, 0.05)
    for _ in range(20):
        counter.update(0.05, 0.05)  # 1 deg/s drift: not a turn
    counter.update(0.0, 0.05)
    assert counter.turns == 1


def test_snapshot_has_readings_by_port():
    session = Session(ROOM, "erobotic", noise="off")
    snap = session.snapshot()
    assert set(snap.readings) == {1, 2, 3}
    assert snap.block == (3, 2)
    assert snap.state is None and str(snap.driver) == "nobody"


def test_reset_returns_to_the_start_and_clears_metrics():
    session = Session(CORRIDOR, "erobotic", noise="off")
    session.command(WheelPowers(1, 1))
    session.run(max_time=2)
    session.reset()
    assert session.world.time == 0
    assert session.metrics().distance == 0
    assert session.snapshot().block == CORRIDOR.start


def test_record_has_header_ticks_and_summary(tmp_path):
    path = tmp_path / "run.jsonl"
    recorder = Recorder(path)
    session = Session(CORRIDOR, "erobotic", noise="off", recorder=recorder)
    session.record_header(algorithm="keyboard", params={})
    session.command(MoveAtPower(1.0))
    session.run(max_time=30)
    session.record_summary(final_state=None, cut_by_limit=False)
    recorder.close()
    record = read_record(path)
    assert record.header["format"] == FORMAT
    assert record.header["maze"]["digest"] == CORRIDOR.digest()
    assert record.header["sensors"] == ["distance:1:front", "distance:2:left", "distance:3:right"]
    assert record.summary["reached_exit"] is True
    assert record.ticks[0]["cmd"] == [{"move": 1.0}]
    assert record.ticks[-1]["events"] == ["exit"]
    # one line per control tick (20 Hz)
    assert len(record.ticks) == pytest.approx(record.summary["sim_time"] * 20, abs=1)


def test_cut_short_record_loads_without_summary(tmp_path):
    buf = io.StringIO()
    recorder = Recorder(buf)
    session = Session(CORRIDOR, "erobotic", noise="off", recorder=recorder)
    session.record_header()
    session.run(max_time=1)
    path = tmp_path / "cut.jsonl"
    path.write_text(buf.getvalue())
    assert read_record(path).summary is None


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("", "empty file"),
        ('{"type":"header","format":"other"}\n', "not a workbench run record"),
        (f'{{"type":"header","format":"{FORMAT}"}}\n{{oops\n', ":2: not JSON"),
        (f'{{"type":"header","format":"{FORMAT}"}}\n[1]\n', ":2: each line must be a JSON object"),
    ],
)
def test_bad_records_are_clear_errors(tmp_path, text, message):
    path = tmp_path / "bad.jsonl"
    path.write_text(text)
    with pytest.raises(RecordError, match=message):
        read_record(path)


def test_record_lines_are_compact_json(tmp_path):
    buf = io.StringIO()
    session = Session(CORRIDOR, "erobotic", noise="off", recorder=Recorder(buf))
    session.run(max_time=0.1)
    line = json.loads(buf.getvalue().splitlines()[0])
    assert set(line) == {"t", "pose", "sensors"}


def test_a_new_maze_goes_into_the_same_session_with_its_setup():
    session = Session(ROOM, "erobotic", noise="low", seed=7)
    session.set_sensors(session.world.sensors[:1])
    sensors, noise = session.world.sensors, session.world.noise
    session.command(MoveAtPower(1.0), driver=Driver.program("a script"))
    session.run(max_time=1)
    session.load_maze(CORRIDOR)
    assert session.maze is CORRIDOR and session.world.maze is CORRIDOR
    assert (session.world.sensors, session.world.noise, session.world.seed) == (sensors, noise, 7)
    assert session.world.block == CORRIDOR.start and session.metrics().distance == 0
    session.command(MoveAtPower(1.0))
    assert session.run(max_time=30).reached_exit  # the corridor's exit, on the new maze


class _Dues:
    """A controller with things due at the given times, in order: it notes when each one
    is reached (the first tick at or within a nanosecond after it)."""

    state = None

    def __init__(self, dues: list[float]) -> None:
        self.variables: dict = {}
        self.dues = list(dues)
        self.reached: list[tuple[float, float]] = []

    def start(self, t):
        return []

    def tick(self, t, readings, events):
        while self.dues and t + 1e-9 >= self.dues[0]:
            self.reached.append((self.dues.pop(0), t))
        return []

    def next_due(self):
        return self.dues[0] if self.dues else None


def test_a_controller_is_woken_at_each_time_it_has_something_due_and_no_other():
    """Inside a step, on a step's end, a hair before or after one, on a control tick, far
    off: each due time is reached at that very time (to the nanosecond), never early."""
    dt = 1 / 60
    # (the controller starts at the first control tick, 0.05 s, and is asked from then on)
    dues = [0.051, 0.0605, 5 * dt, 7 * dt - 4e-10, 8 * dt + 4e-10, 0.25, 0.2501, 0.3, 1.0]
    dues += [1.0 + 1e-10, 2.0 - 5e-9, 2.5, 1e297]
    controller = _Dues(dues)
    session = Session(ROOM, "erobotic", noise="off")
    session.attach(controller, {}, Driver.program("dues"))
    session.run(max_time=3.0)
    assert controller.dues == [1e297]  # far beyond the run: never reached
    assert [d for d, _ in controller.reached] == dues[:-1]
    for due, t in controller.reached:
        assert due - 1e-9 <= t <= due + 1e-9, (due, t)


class _Readings:
    """A controller that notes the readings it is given by name."""

    def __init__(self) -> None:
        self.seen: list[dict[str, object]] = []

    def start(self, t: float) -> list:
        return []

    def tick(self, t: float, readings: dict, events: frozenset) -> list:
        self.seen.append(dict(readings))
        return []


def test_a_controller_gets_its_readings_by_the_names_of_its_binding():
    session = Session(ROOM, "erobotic", noise="off")
    controller = _Readings()
    ports = [spec.port for spec in session.world.sensors]
    session.attach(controller, {"first": ports[0]}, Driver.program("names"))
    session.run(max_time=0.2)
    assert controller.seen and set(controller.seen[-1]) == {"first"}
    # a new binding is a new mapping, which the next tick uses; the one read is not changed
    with pytest.raises(TypeError):
        session.binding["second"] = ports[1]  # type: ignore[index]
    session.binding = {"second": ports[-1]}
    session.run(max_time=0.4)
    assert set(controller.seen[-1]) == {"second"}
    assert controller.seen[-1]["second"] == session.readings[ports[-1]]
