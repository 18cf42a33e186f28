"""The simulated robot in a maze: motion, turns, sensors, walls, noise, odometry, profiles."""

from __future__ import annotations

import math

import pytest

from workbench.sim.commands import MotorPower, MoveAtPower, Stop, TurnByDegrees, WheelPowers
from workbench.sim.maze import Maze
from workbench.sim.noise import NoiseSettings, noise_settings
from workbench.sim.profiles import PROFILES, get_profile
from workbench.sim.sensors import SensorConfigError, SensorSpec
from workbench.sim.world import (
    COLLISION,
    EXIT,
    TOUCH,
    TURN_DONE,
    World,
    WorldError,
    wall_segments,
)

ALL_MOUNTS = [
    SensorSpec("distance", 1, "front"),
    SensorSpec("distance", 2, "right"),
    SensorSpec("distance", 3, "back"),
    SensorSpec("distance", 4, "left"),
]
ALL_TOUCH = [
    SensorSpec("touch", 5, "front"),
    SensorSpec("touch", 6, "right"),
    SensorSpec("touch", 7, "back"),
    SensorSpec("touch", 8, "left"),
]


def maze(*rows: str, start=(1, 1), heading="right", exits=()) -> Maze:
    return Maze(rows=rows, start=start, heading=heading, exits=exits)


def corridor(length: int, heading: str = "right", exit_at_end: bool = False) -> Maze:
    """A one-block corridor along a row; the robot starts at its left end."""
    middle = "#" + "." * length + ("." if exit_at_end else "#")
    rows = ("#" * (length + 2), middle, "#" * (length + 2))
    exits = ((length + 1, 1),) if exit_at_end else ()
    return maze(*rows, start=(1, 1), heading=heading, exits=exits)


def angle_between(a: float, b: float) -> float:
    return abs((a - b + 180.0) % 360.0 - 180.0)


def run_until(world: World, condition, seconds: float) -> bool:
    for _ in range(round(seconds / world.dt)):
        world.step()
        if condition():
            return True
    return False


# -- straight moves and turns ------------------------------------------------------------
def test_driving_three_blocks_measures_three_blocks():
    world = World(corridor(8), "erobotic", noise="off")
    cell = world.cell
    x0, y0, heading0 = world.pose
    world.apply(MoveAtPower(1.0))  # erobotic: one block per second at full power
    reached = run_until(world, lambda: world.pose.x - x0 >= 3 * cell, 4.0)
    world.apply(Stop())
    world.run(0.5)
    assert reached
    x, y, heading = world.pose
    assert x - x0 == pytest.approx(3 * cell, rel=0.01)
    assert y == pytest.approx(y0)
    assert heading == pytest.approx(heading0)
    odo = world.odometry
    assert odo.distance == pytest.approx(3 * cell, rel=0.01)
    assert odo.turn_degrees == pytest.approx(0.0, abs=1e-9)
    assert odo.collisions == 0


def test_four_right_turns_make_a_full_circle_and_each_reports_done_once():
    world = World(corridor(3), "erobotic", noise="off")
    start = world.pose
    for _ in range(4):
        world.apply(TurnByDegrees(90))
        events = world.run(3.0)
        assert [e for _, e in events] == [TURN_DONE]
        assert not world.turning
    odo = world.odometry
    assert odo.turn_degrees == pytest.approx(360.0, abs=1.0)
    assert angle_between(world.pose.heading, start.heading) < 0.01
    assert world.pose.x == pytest.approx(start.x) and world.pose.y == pytest.approx(start.y)
    assert odo.distance == pytest.approx(0.0, abs=1e-6)


def test_turn_goes_right_for_positive_degrees_and_left_for_negative():
    world = World(corridor(3), "erobotic", noise="off")
    world.apply(TurnByDegrees(90))
    world.run(2.0)
    assert world.pose.heading == pytest.approx(90.0, abs=1e-3)  # facing down the page
    world.apply(TurnByDegrees(-180))
    world.run(3.0)
    assert world.pose.heading == pytest.approx(270.0, abs=1e-3)  # facing up the page


def test_turn_takes_the_profile_rate():
    world = World(corridor(3), "unity", noise="off")
    world.apply(TurnByDegrees(90))
    events = world.run(4.0)
    done = [t for t, e in events if e == TURN_DONE]
    assert done and done[0] == pytest.approx(90 / 35, abs=0.1)  # Unity turns at 35 deg/s


def test_a_new_command_cancels_a_turn_in_progress():
    world = World(corridor(3), "erobotic", noise="off")
    world.apply(TurnByDegrees(90))
    world.run(0.5)
    world.apply(Stop())
    events = world.run(2.0)
    assert TURN_DONE not in [e for _, e in events]
    assert not world.turning
    assert 30 < world.pose.heading < 60


def test_zero_degree_turn_is_done_on_the_next_step():
    world = World(corridor(3), "erobotic", noise="off")
    world.apply(TurnByDegrees(0))
    assert world.step() == (TURN_DONE,)


def test_motor_power_on_the_left_wheel_alone_curves_right():
    world = World(maze("#######", "#.....#", "#.....#", "#.....#", "#######", start=(2, 2)), "web")
    world.apply(MotorPower("left", 0.3))
    world.run(1.0)
    assert 10 < world.pose.heading < 180  # turned clockwise: to the right
    world.apply(MotorPower("right", 0.3))  # left keeps its power: now straight
    world.step()
    heading = world.pose.heading
    world.run(0.5)
    assert world.pose.heading == pytest.approx(heading, abs=0.1)


def test_unity_move_at_power_goes_one_unit_per_second_whatever_the_power():
    world = World(corridor(10), "unity", noise="off")
    for power in (0.3, 1.0, -0.3):
        world.apply(MoveAtPower(power))
        world.run(0.5)
        x0 = world.pose.x
        world.run(2.0)
        assert world.pose.x - x0 == pytest.approx(math.copysign(2.0, power), rel=0.01)


def test_web_spin_at_point_two_for_one_and_a_half_seconds_is_a_quarter_turn():
    world = World(maze("#####", "#...#", "#...#", "#...#", "#####", start=(2, 2)), "web")
    x0, y0, h0 = world.pose
    world.apply(WheelPowers(0.2, -0.2))
    world.run(1.5)
    world.apply(WheelPowers(0, 0))
    world.run(0.5)
    x, y, h = world.pose
    assert h - h0 == pytest.approx(90.0, abs=10.0)
    assert math.hypot(x - x0, y - y0) < 1.0


def test_web_half_power_crosses_a_block_in_about_a_second():
    world = World(corridor(6), "web", noise="off")
    x0 = world.pose.x
    world.apply(WheelPowers(0.5, 0.5))
    world.run(1.0)
    assert world.pose.x - x0 == pytest.approx(world.cell, rel=0.05)


# -- sensors -----------------------------------------------------------------------------
ROOM = (
    "########",
    "#......#",
    "#......#",
    "#..#...#",
    "########",
)


def test_distance_sensors_read_hand_computed_distances_on_every_mount():
    # erobotic: block 120 px, sensors on the edge of a robot of radius 8
    world = World(maze(*ROOM, start=(3, 1), heading="down"), "erobotic", sensors=ALL_MOUNTS)
    assert world.pose[:2] == (420.0, 180.0)
    readings = world.read_sensors()
    assert readings[1] == pytest.approx(360 - 180 - 8)  # front: the # below, at y = 360
    assert readings[2] == pytest.approx(420 - 120 - 8)  # right of "down" is screen-left
    assert readings[3] == pytest.approx(180 - 120 - 8)  # back: the top wall
    assert readings[4] == pytest.approx(840 - 420 - 8)  # left of "down" is screen-right


def test_distance_sensor_at_an_angle_hits_the_first_face_on_the_ray():
    world = World(maze(*ROOM, start=(1, 2)), "erobotic", sensors=ALL_MOUNTS[:1])
    world.apply(TurnByDegrees(45))
    world.run(1.0)
    # from (180, 300) heading down-right the ray meets the bottom wall (y = 480) first
    assert world.read_sensors()[1] == pytest.approx((480 - 300) * math.sqrt(2) - 8, abs=1e-6)


def test_distance_beyond_range_reports_no_echo():
    world = World(corridor(60), "unity", noise="off")  # 120 units of corridor, range 100
    readings = world.read_sensors()
    assert readings[2] == 1000  # front: Unity's "nothing hit"
    assert readings[1] == pytest.approx(1.0 - 0.45)  # right: the corridor wall


def test_touch_reads_one_against_a_wall_and_zero_away_from_it():
    world = World(corridor(4), "web", sensors=ALL_TOUCH, noise="off")
    assert world.read_sensors() == {5: 0, 6: 0, 7: 0, 8: 0}
    world.apply(WheelPowers(0.5, 0.5))
    assert run_until(world, lambda: world.read_sensors()[5] == 1, 6.0)
    world.run(1.0)  # keeps pushing: stays pressed, only the front
    assert world.read_sensors() == {5: 1, 6: 0, 7: 0, 8: 0}
    world.apply(WheelPowers(-0.3, -0.3))
    world.run(0.5)
    assert world.read_sensors() == {5: 0, 6: 0, 7: 0, 8: 0}


def test_touch_on_the_side_that_rubs_the_wall():
    world = World(corridor(6), "web", sensors=ALL_TOUCH, noise="off")
    world.apply(TurnByDegrees(20))  # aim at the right-hand wall
    world.run(1.0)
    world.apply(WheelPowers(0.5, 0.5))
    world.run(2.0)  # now sliding along the wall on the right
    readings = world.read_sensors()
    assert readings[6] == 1 and readings[8] == 0


def test_readings_are_stable_within_a_step_and_change_with_noise_across_steps():
    world = World(corridor(4), "unity", noise="realistic", seed=3)
    first = world.read_sensors()
    assert world.read_sensors() == first
    world.step()
    assert world.read_sensors() != first


def test_duplicate_ports_are_rejected_naming_both_sensors():
    world = World(corridor(3), "web")
    with pytest.raises(SensorConfigError) as err:
        world.set_sensors([SensorSpec("distance", 1, "right"), SensorSpec("touch", 1, "front")])
    assert "distance:1:right" in str(err.value) and "touch:1:front" in str(err.value)
    with pytest.raises(SensorConfigError):
        World(corridor(3), "unity", sensors=[SensorSpec("distance", 2, "right")] * 2)


def test_sensors_can_be_changed_live():
    world = World(corridor(3), "erobotic")
    assert set(world.read_sensors()) == {1, 2, 3}
    world.set_sensors([SensorSpec("touch", 9, "back")])
    assert world.read_sensors() == {9: 0}


def test_profile_default_sensors():
    assert [str(s) for s in get_profile("unity").sensors] == [
        "distance:1:right",
        "distance:2:front",
    ]
    assert [str(s) for s in get_profile("web").sensors] == ["distance:1:right", "touch:2:front"]
    assert [str(s) for s in get_profile("erobotic").sensors] == [
        "distance:1:front",
        "distance:2:left",
        "distance:3:right",
    ]


# -- walls -------------------------------------------------------------------------------
def assert_clear_of_walls(world: World, slack: float) -> None:
    m = world.maze
    x, y, _ = world.pose
    bx, by = world.block
    assert not m.is_wall(bx, by), f"centre inside a wall block at {(bx, by)}"
    r = world.profile.robot_radius
    c = world.cell
    for j in range(by - 1, by + 2):
        for i in range(bx - 1, bx + 2):
            if m.is_wall(i, j):
                nx = min(max(x, i * c), (i + 1) * c) - x
                ny = min(max(y, j * c), (j + 1) * c) - y
                assert math.hypot(nx, ny) >= r - slack, f"robot inside wall block {(i, j)}"


@pytest.mark.parametrize("profile", sorted(PROFILES))
def test_full_power_into_walls_and_corners_never_gets_through(profile):
    world = World(
        maze(
            "#######",
            "#.....#",
            "#.#.#.#",
            "#.....#",
            "#..#...",
            "#######",
            start=(3, 3),
            exits=((6, 4),),
        ),
        profile,
        noise="realistic",
        seed=11,
    )
    p = world.profile
    # a block's worth of travel in one step at most, plus the contact slop
    slack = max(p.max_wheel_speed, p.move_speed) * world.dt + 0.002 * world.cell
    drives = [
        WheelPowers(1, 1),
        WheelPowers(1, 0.7),
        WheelPowers(-1, -0.8),
        WheelPowers(1, -1),
        WheelPowers(0.4, 1),
        MoveAtPower(1.0),
        MoveAtPower(-1.0),
    ]
    for k in range(round(20 / world.dt)):
        if k % 90 == 0:
            world.apply(drives[(k // 90) % len(drives)])
        world.step()
        assert_clear_of_walls(world, slack)
    assert world.odometry.collisions > 0


def test_exit_on_the_boundary_is_reached_but_the_world_stays_closed():
    world = World(corridor(4, exit_at_end=True), "web", noise="off")
    world.apply(WheelPowers(1, 1))
    events = world.run(6.0)
    exits = [t for t, e in events if e == EXIT]
    assert len(exits) == 1
    assert world.odometry.exit_time == exits[0]
    assert world.block == (5, 1)
    assert world.pose.x < 6 * world.cell  # stopped at the edge of the grid
    assert world.in_contact


def test_one_collision_per_bump_not_per_step_of_pushing():
    world = World(corridor(3), "web", noise="off")
    world.apply(WheelPowers(1, 1))
    events = world.run(5.0)
    assert [e for _, e in events] == [COLLISION]
    world.apply(WheelPowers(-1, -1))
    world.run(0.5)
    world.apply(WheelPowers(1, 1))
    world.run(2.0)
    assert world.odometry.collisions == 2


def test_a_front_bumper_meeting_the_wall_at_driving_speed_is_a_touch_not_a_collision():
    bumper = [SensorSpec("distance", 1, "right"), SensorSpec("touch", 2, "front")]
    world = World(corridor(3), "web", bumper, noise="off")
    world.apply(WheelPowers(0.5, 0.5))  # the course's Forward: one block a second
    events = world.run(5.0)
    assert [e for _, e in events] == [TOUCH]
    assert world.read_sensors()[2] == 1
    odo = world.odometry
    assert (odo.touches, odo.collisions) == (1, 0)


def test_ramming_a_wall_is_a_collision_even_with_a_bumper():
    bumper = [SensorSpec("touch", 2, "front")]
    world = World(corridor(3), "web", bumper, noise="off")
    world.apply(WheelPowers(1, 1))  # two blocks a second, beyond the touch speed
    events = world.run(5.0)
    assert [e for _, e in events] == [COLLISION]
    assert (world.odometry.touches, world.odometry.collisions) == (0, 1)


def test_a_wall_met_where_no_bumper_is_is_a_collision():
    behind = [SensorSpec("touch", 2, "front")]
    world = World(corridor(3), "web", behind, noise="off")
    world.apply(WheelPowers(-0.5, -0.5))  # backing into the wall behind the start
    events = world.run(3.0)
    assert [e for _, e in events] == [COLLISION]
    world.set_sensors([SensorSpec("touch", 2, "back")])
    world.reset()
    world.apply(WheelPowers(-0.5, -0.5))
    assert [e for _, e in world.run(3.0)] == [TOUCH]


def test_wall_faces_are_merged_into_long_segments():
    room = maze("#####", "#...#", "#...#", "#...#", "#####", start=(2, 2))
    assert sorted(wall_segments(room)) == [
        ((1, 1), (1, 4)),
        ((1, 1), (4, 1)),
        ((1, 4), (4, 4)),
        ((4, 1), (4, 4)),
    ]


# -- noise and replay --------------------------------------------------------------------
def drive_and_trace(world: World) -> list[tuple[float, float, float]]:
    trace = []
    commands = [WheelPowers(0.8, 0.8), TurnByDegrees(90), MoveAtPower(0.6), TurnByDegrees(-45)]
    for k in range(600):
        if k % 150 == 0:
            world.apply(commands[k // 150])
        world.step()
        world.read_sensors()
        trace.append(tuple(world.pose))
    return trace


def test_same_seed_same_run_different_seed_different_run():
    room = maze("#########", "#.......#", "#.......#", "#.......#", "#########", start=(2, 2))
    a = drive_and_trace(World(room, "web", noise="realistic", seed=7))
    b = drive_and_trace(World(room, "web", noise="realistic", seed=7))
    c = drive_and_trace(World(room, "web", noise="realistic", seed=8))
    assert a == b
    assert a != c
    replay = World(room, "web", noise="realistic", seed=7)
    drive_and_trace(replay)
    replay.reset()
    assert drive_and_trace(replay) == a
    assert replay.odometry.time == pytest.approx(10.0)


def test_reset_returns_to_the_start_and_clears_the_run():
    world = World(corridor(5, exit_at_end=True), "erobotic")
    start = world.pose
    world.apply(MoveAtPower(1.0))
    world.run(8.0)
    assert world.odometry.exit_time is not None
    world.reset()
    assert world.pose == start
    assert world.odometry.time == 0 and world.odometry.distance == 0
    assert world.odometry.exit_time is None and world.odometry.collisions == 0
    world.run(1.0)
    assert world.pose == start  # motors were stopped by the reset


def test_noise_settings_levels_and_overrides():
    unity = get_profile("unity")
    assert not noise_settings("off", unity).enabled
    realistic = noise_settings("realistic", unity, turn_error=0.1)
    assert realistic.turn_error == 0.1 and realistic.motor_imbalance > 0
    assert realistic.distance_absolute == pytest.approx(0.005 * unity.cell)
    with pytest.raises(ValueError, match="off, low, realistic"):
        noise_settings("loud", unity)
    with pytest.raises(ValueError, match="turn_eror"):
        noise_settings("low", unity, turn_eror=0.1)
    with pytest.raises(ValueError, match="turn_error"):
        NoiseSettings(turn_error=-1)


def test_turn_error_changes_how_far_a_turn_goes():
    turns = []
    for seed in (1, 2):
        noise = noise_settings("off", get_profile("erobotic"), turn_error=0.05)
        world = World(corridor(3), "erobotic", noise=noise, seed=seed)
        world.apply(TurnByDegrees(90))
        world.run(2.0)
        turns.append(world.odometry.turn_degrees)
    assert turns[0] != pytest.approx(turns[1], abs=0.1)
    assert all(70 < t < 110 for t in turns)


# -- profiles and the course's thresholds ---------------------------------------------------
@pytest.mark.parametrize("name", sorted(PROFILES))
def test_course_thresholds_work_in_a_one_block_corridor(name):
    """Centred: side below "open"; an opening above it; "blocked" before touching the wall."""
    world = World(
        maze(
            "########",
            "#......#",
            "####.###",
            "####.###",
            "########",
            start=(1, 1),
        ),
        name,
        sensors=[SensorSpec("distance", 1, "front"), SensorSpec("distance", 2, "right")],
        noise="off",
    )
    p = world.profile
    assert world.read_sensors()[2] < p.open_above
    if name == "erobotic":
        assert world.read_sensors()[2] >= 50  # one-distance-first: "right < 50" is too close
    if name == "web":
        assert world.read_sensors()[2] == pytest.approx(25)  # the programs' BaseDistance
    world.apply(WheelPowers(0.5, 0.5))
    assert run_until(world, lambda: world.read_sensors()[2] > p.open_above, 30.0)
    assert world.read_sensors()[2] > p.open_above * 1.5  # clearly open, not marginal
    assert run_until(world, lambda: world.read_sensors()[1] < p.blocked_below, 30.0)
    world.apply(Stop())
    world.run(0.5)
    assert world.odometry.collisions == 0
    assert not world.in_contact
    # stopped close to the centre of the last block, ready to turn into the next corridor
    last_centre = 6.5 * world.cell
    assert abs(world.pose.x - last_centre) < 0.1 * world.cell


def test_unknown_profile_lists_the_names():
    with pytest.raises(ValueError, match="unity, web, erobotic"):
        get_profile("lego")


def test_world_refuses_a_maze_without_a_start_or_with_blocks_too_small():
    with pytest.raises(WorldError, match="no start"):
        World(Maze(rows=("###", "#.#", "###")), "unity")
    tiny = Maze(rows=("###", "#.#", "###"), start=(1, 1), profile="web", cell=15)
    with pytest.raises(WorldError, match="does not fit"):
        World(tiny, "web")


def test_a_mazes_own_block_size_is_used_for_its_profile():
    m = Maze(rows=("###", "#.#", "###"), start=(1, 1), profile="unity", cell=1.0)
    assert World(m, "unity").cell == 1.0
    assert World(m, "unity").pose[:2] == (1.5, 1.5)
    assert World(m, "web").cell == get_profile("web").cell  # written for another profile
