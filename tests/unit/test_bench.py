"""The live workbench behind the app: keys, sensor panel, algorithms, runs."""

import pytest

from workbench.control.station import (
    ALGORITHM_FAILED,
    OUT,
    LabStation,
    Notice,
    SensorRow,
    check_sensor_rows,
)
from workbench.fsm.machine import SensorBindingError
from workbench.sim.driver import Driver
from workbench.sim.mazefile import parse_maze
from workbench.sim.mazeio import load_maze
from workbench.sim.sensors import SensorSpec

CORRIDOR = parse_maze("##########\n#S......E#\n##########\n", source="corridor.txt")
ROOM = parse_maze("#######\n#.....#\n#..S..#\n#.....#\n#######\n", source="room.txt")


def station(maze=ROOM, profile="erobotic", **kw):
    return LabStation.open(maze, profile, noise="off", **kw)


def test_unity_keys_move_and_turn_like_the_course_key_program():
    b = station(profile="unity")
    b.key("d")
    b.step(60 * 4)
    assert b.snapshot().pose.heading == pytest.approx(90, abs=0.5)  # facing down the page
    b.key("w")
    b.step(30)
    assert b.snapshot().pose.y > ROOM.start[1] * 2 + 1  # moved down
    b.key("space")
    y = b.snapshot().pose.y
    b.step(30)
    assert b.snapshot().pose.y == pytest.approx(y, abs=0.02)
    assert b.keys_used == {"d", "w", "space"} and str(b.snapshot().driver) == "keys"


def test_web_keys_spin_until_the_next_key():
    b = station(profile="web")
    b.key("a")
    b.step(90)  # (-0.2, 0.2) for 1.5 s: about 90 degrees left
    assert b.snapshot().pose.heading == pytest.approx(270, abs=10)
    b.key("space")
    h = b.snapshot().pose.heading
    b.step(30)
    assert b.snapshot().pose.heading == pytest.approx(h, abs=0.01)


def test_erobotic_w_moves_exactly_one_block_and_stops():
    b = station(CORRIDOR)
    b.key("w")
    b.step(120)
    snap = b.snapshot()
    assert snap.block == (CORRIDOR.start[0] + 1, CORRIDOR.start[1])
    assert snap.metrics.distance_cells == pytest.approx(1.0, abs=1e-6)


def test_non_drive_keys_are_ignored():
    assert station().key("x") is False


def test_sensor_rows_are_checked_and_nothing_applied_on_error():
    b = station()
    before = list(b.sensors)
    errors = b.apply_sensor_rows(
        [SensorRow("distance", "1", "right"), SensorRow("touch", "1", "front"),
         SensorRow("distance", "x", "left"), SensorRow("distance", "120", "back")]
    )  # fmt: skip
    assert errors == {
        0: "port 1 is also used by row 2",
        1: "port 1 is already used by row 1",
        2: "port 'x' is not a whole number",
        3: "port 120 is out of range (0-99)",
    }
    assert b.sensors == before


def test_unmounted_rows_are_left_out_and_readings_follow_the_new_ports():
    b = station()
    assert (
        b.apply_sensor_rows([SensorRow("distance", "7", "front"), SensorRow("touch", "2", None)])
        == {}
    )
    assert b.sensors == [SensorSpec("distance", 7, "front")]
    assert set(b.snapshot().readings) == {7}


def test_check_sensor_rows_returns_specs_in_row_order():
    specs, errors = check_sensor_rows([SensorRow("touch", " 4 ", "back")])
    assert specs == [SensorSpec("touch", 4, "back")] and errors == {}


def test_presets_of_the_course_simulators():
    b = station()
    b.apply_preset("web-two-distance")
    assert b.sensors == [SensorSpec("distance", 3, "front")]


def test_missing_sensor_is_explained_and_fixed_with_the_preset():
    b = station()
    b.apply_preset("web-two-distance")
    b.select_algorithm("right-wall")
    assert "needs a distance sensor mounted right" in b.missing_sensors()
    with pytest.raises(SensorBindingError):
        b.start()
    b.apply_algorithm_preset()
    assert b.missing_sensors() is None
    b.start()
    assert str(b.snapshot().driver) == "algorithm right-wall"


def test_algorithm_run_to_the_exit_is_recorded_in_runs(tmp_path):
    b = station(load_maze("mazes/rank-wall-wins.txt"), record_dir=str(tmp_path))
    b.select_algorithm("right-wall")
    b.start()
    for _ in range(200):
        b.step(60)
        if b.runs:
            break
    run = b.runs[0]
    assert run.ended == "exit" and run.metrics.reached_exit
    assert str(run.driver) == "algorithm right-wall"
    assert b.pacer.paused
    assert (tmp_path / "run-001.jsonl").read_text().splitlines()[-1].startswith('{"type":"summary"')


def test_parameters_are_validated_before_any_is_kept():
    b = station()
    b.select_algorithm("right-wall")
    with pytest.raises(ValueError, match="not a number"):
        b.set_params(["open_right=120", "front_blocked=near"])
    assert b.params()["open_right"] == 100
    assert b.set_params(["open_right=120"])["open_right"] == 120
    b.reset_params()
    assert b.params()["open_right"] == 100


def test_keys_take_over_from_an_algorithm_and_close_its_run():
    b = station(load_maze("mazes/erobotic.txt"))
    b.select_algorithm("farthest-distance")
    b.start()
    b.step(60)
    b.key("space")
    assert b.driving is None and b.runs[-1].ended == "stopped"
    assert str(b.snapshot().driver) == "keys"


def test_reset_robot_returns_to_start_and_loading_a_maze_restarts():
    b = station(CORRIDOR)
    b.key("w")
    b.step(60)
    b.reset_robot()
    assert b.snapshot().block == CORRIDOR.start and b.runs[-1].ended == "reset"
    b.load_maze(ROOM)
    assert b.snapshot().block == ROOM.start


def test_sensor_rows_pad_the_live_sensors_like_the_web_simulator_panel():
    b = station(profile="unity")
    assert b.sensor_rows() == [
        SensorRow("distance", "1", "right"),
        SensorRow("distance", "2", "front"),
        SensorRow("touch", "3", None),
    ]
    b.apply_preset("web-two-distance")
    assert b.sensor_rows() == [
        SensorRow("distance", "3", "front"),
        SensorRow("distance", "1", None),
        SensorRow("touch", "2", None),
    ]
    assert b.apply_sensor_rows(b.sensor_rows()) == {}
    assert b.sensors == [SensorSpec("distance", 3, "front")]


FAILING_FSM = """\
name: failing
sensors:
  front: {kind: distance, mount: front, port: {unity: 2, web: 2, erobotic: 1}}
initial: Go
states:
  Go:
    on_enter:
      - move: 1
    transitions:
      - when: 1 / (front - front) > 0
        to: Go
"""


@pytest.mark.parametrize("how", ["step", "advance"])
def test_a_failing_algorithm_is_stopped_with_the_reason_instead_of_raising(tmp_path, how):
    path = tmp_path / "failing.yaml"
    path.write_text(FAILING_FSM)
    b = station()
    b.select_algorithm(path)
    b.start()
    if how == "step":
        b.step(30)
    else:
        b.advance(0.5)
    assert b.driving is None and b.pacer.paused
    assert b.notice.kind == ALGORITHM_FAILED
    assert b.notice.detail.startswith("failing, state Go: guard")
    assert b.runs[-1].ended == "error"
    assert str(b.snapshot().driver) == "keys"


def test_a_new_maze_keeps_pause_and_frame_budget_and_starts_at_1x():
    b = station()
    b.toggle_pause()
    assert b.next_speed()
    b.pacer.budget = 0.03
    b.load_maze(CORRIDOR)
    assert (b.pacer.paused, b.pacer.speed, b.pacer.budget) == (True, 1.0, 0.03)
    assert b.pacer.session is b.session and b.snapshot().block == CORRIDOR.start


MOVE = '{"servos":[{"isTurn":false,"servoId":-1,"servoSpeed":1}]}'


def test_a_viple_program_that_drives_is_recorded_with_its_role_and_a_run():
    from workbench.viple.link import Link

    b = station(CORRIDOR, profile="unity")
    b.key("w")
    b.step(10)
    b.key("space")
    b.step(10)
    link = Link(b, "tcp")
    assert link.connect("127.0.0.1:50312")
    b.step(1)
    assert [(c.role, c.peer, c.drove) for c in b.viple] == [("tcp", "127.0.0.1:50312", False)]
    assert str(b.runs[-1].driver) == "keys" and b.runs[-1].ended == "stopped"
    assert link.apply(MOVE)
    b.step(60)
    assert b.viple[0].drove and b.viple[0].distance > 0.5
    link.disconnect()
    b.step(1)
    run = b.runs[-1]
    assert (run.driver, run.ended, run.source) == (
        Driver.viple("tcp", "127.0.0.1:50312"),
        "stopped",
        None,
    )
    assert run.maze_digest == CORRIDOR.digest()
    assert len(b.viple) == 1


def test_a_viple_program_that_only_connects_has_not_driven():
    from workbench.viple.link import Link

    b = station(CORRIDOR, profile="unity")
    link = Link(b, "ws", "ws://localhost:8124/")
    link.connect("ws://localhost:8124/")
    b.step(30)
    link.disconnect()
    b.step(1)
    assert [(c.role, c.drove) for c in b.viple] == [("ws", False)]


def test_a_viple_program_that_takes_the_robot_from_an_algorithm_ends_its_run():
    from workbench.viple.link import Link

    b = station(CORRIDOR, profile="unity")
    b.select_algorithm("right-wall")
    b.start()
    b.step(20)
    Link(b, "tcp").connect("127.0.0.1:1")
    b.step(1)
    assert b.driving is None
    assert str(b.runs[-1].driver) == "algorithm right-wall"
    assert b.runs[-1].source.endswith("right-wall.yaml")


def test_an_attempt_keeps_apart_keys_and_viple_seen_before_but_not_the_one_driving():
    from workbench.viple.link import Link

    b = station(CORRIDOR, profile="unity")
    for key in ("w", "a"):
        b.key(key)
    old = Link(b, "ws", "ws://localhost:8124/")
    old.connect("ws://localhost:8124/")
    old.apply(MOVE)
    b.step(30)
    old.disconnect()
    link = Link(b, "tcp")
    link.connect("127.0.0.1:50400")
    b.step(1)
    attempt = b.begin_attempt("lab", "ex")
    assert b.keys_used == set()
    mine = [c for c in b.viple if c.attempt == attempt.id]
    assert [(c.role, c.peer, c.drove) for c in mine] == [("tcp", "127.0.0.1:50400", False)]
    link.apply(MOVE)
    b.step(60)
    assert mine[0].drove and mine[0].distance > 0.5  # the driving after the start counts
    assert {u.key for u in b.key_uses if u.attempt == ""} == {"w", "a"}  # kept, apart


def test_after_a_run_ends_at_the_exit_the_next_drive_key_drives():
    b = station(load_maze("mazes/rank-wall-wins.txt"), "unity")
    b.select_algorithm("right-wall")
    b.apply_algorithm_preset()
    b.start()
    while not b.runs:
        b.step(60)
    assert b.pacer.paused and b.notice == Notice(OUT)
    b.reset_robot()
    b.load_maze(load_maze("mazes/rank-local-best-wins.txt"))
    assert not b.pacer.paused  # reset and a new maze: time runs again
    b.key("w")
    b.advance(0.5)
    assert b.snapshot().metrics.distance > 0


def test_a_pause_the_user_chose_stays_until_they_resume():
    b = station(profile="unity")
    assert b.toggle_pause()
    b.key("w")
    b.advance(0.5)
    assert b.pacer.paused and b.snapshot().metrics.distance == 0


def test_a_viple_program_drives_on_after_the_maze_is_changed_under_it():
    from workbench.viple.link import Link

    b = LabStation.open(ROOM, "erobotic", noise="off")
    session = b.session
    link = Link(b, "tcp")
    assert link.connect("127.0.0.1:50312")
    b.load_maze(CORRIDOR)
    assert b.session is session and link.session is session  # one session, one reference
    assert link.apply(MOVE)
    b.step(60)
    assert str(b.snapshot().driver) == "VIPLE tcp 127.0.0.1:50312"
    assert b.snapshot().metrics.distance > 0.5 and b.session.world.maze is CORRIDOR


def test_pausing_is_one_switch_on_the_station():
    b = LabStation.open(ROOM, "erobotic", noise="off")
    b.pause()
    assert b.paused and b.advance(1.0) == 0
    assert b.toggle_pause() is False and not b.paused
    assert b.advance(0.5) > 0


def test_one_driving_slot_the_latest_choice_drives_and_stops_one_way():
    from workbench.program.choice import choose_program

    sensors = [SensorSpec.parse("distance:1:right"), SensorSpec.parse("touch:2:front")]
    b = station(load_maze("mazes/web.txt"), "web", sensors=sensors)
    b.select_algorithm("web-wall-following")
    choose_program(b, "programs/right-wall.viple")  # the latest choice wins
    b.start()
    assert str(b.snapshot().driver) == "VIPLE program right-wall.viple" and b.program_drives
    assert b.session.binding == {"port 1": 1, "port 2": 2}  # a program reads sensors by port
    b.apply_sensors([SensorSpec.parse("distance:1:right"), SensorSpec.parse("touch:4:front")])
    assert b.session.binding == {"port 1": 1, "port 4": 4}
    b.step(60)
    b.key("space")  # space stops a program, as it stops the robot
    assert b.driving is None and str(b.snapshot().driver) == "keys"
    assert (b.runs[-1].ended, b.runs[-1].source) == ("stopped", "programs/right-wall.viple")
    b.select_algorithm("web-wall-following")
    b.apply_algorithm_preset()
    b.start()
    assert str(b.snapshot().driver) == "algorithm web-wall-following" and not b.program_drives
    b.step(60)
    b.stop()
    assert b.driving is None and b.runs[-1].driver == Driver.algorithm("web-wall-following")
    with pytest.raises(ValueError, match="choose an algorithm first"):
        LabStation.open(ROOM).start()
