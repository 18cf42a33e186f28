"""A station at rest (paused, or the robot standing with nobody driving it) changes nothing but
its clock, so a front end may tick it seldom: the run comes out the same."""

from __future__ import annotations

import pytest

from workbench.control.station import LabStation
from workbench.sim.clock import SPEEDS
from workbench.sim.mazeio import load_maze

MAZE = "mazes/rank-wall-wins.txt"


def station(**kwargs) -> LabStation:
    return LabStation.open(load_maze(MAZE), seed=3, **kwargs)


def test_a_new_station_is_at_rest_until_a_key_drives_it():
    s = station()
    assert s.at_rest
    s.key("w")
    assert not s.at_rest  # the motors are on
    s.advance(0.5)
    assert not s.at_rest
    s.key("space")
    assert not s.at_rest  # stopped, but it has not stood still for a step yet
    s.step(1)
    assert s.at_rest
    pose, t = s.session.world.pose, s.session.world.time
    s.advance(1.0, lag=1.25)
    assert s.at_rest and s.session.world.pose == pose  # only the clock went on
    assert s.session.world.time == pytest.approx(t + 1.0, abs=1 / 60)


def test_a_turn_an_algorithm_or_max_speed_is_never_rest_but_pause_always_is():
    s = station()
    s.key("a")  # a turn on the spot: nothing moves forward, yet the heading changes
    s.step(1)
    assert not s.at_rest
    s.key("space")
    s.step(1)
    assert s.at_rest
    s.select_algorithm("right-wall")
    s.apply_algorithm_preset()
    s.start()
    assert not s.at_rest
    s.pause()
    assert s.at_rest
    s.pause(False)
    s.stop()
    s.step(1)
    assert s.at_rest
    s.pacer.speed = None  # max: as many steps as the frame allows, so every frame counts
    assert not s.at_rest


def _play(s: LabStation, keys, until: float, rest_tick: float) -> list[tuple]:
    """Tick ``s`` as the app does (20 Hz while things move, once per ``rest_tick`` at rest,
    keeping all the time owed), pressing each (time, key) of ``keys`` when its time comes:
    what the station showed at each key and at ``until``."""
    # a clock that never moves: the frame budget (wall time) never cuts a tick short, so a
    # loaded machine runs the same steps as a quiet one
    s.pacer.clock = lambda: 0.0
    seen = []
    wall = 0.0

    def keep_up(t: float) -> None:
        nonlocal wall
        while wall < t - 1e-9:
            if s.at_rest:
                seconds = min(rest_tick, t - wall)
                s.advance(seconds, rest_tick + s.pacer.max_lag)
            else:
                seconds = min(0.05, t - wall)
                s.advance(seconds)
            wall += seconds

    for at, key in keys:
        keep_up(at)
        s.key(key)
        w = s.session.world
        seen.append((key, round(w.time, 9), w.pose, dict(s.session.readings)))
    keep_up(until)
    w = s.session.world
    seen.append(("end", round(w.time, 9), w.pose, w.odometry))
    return seen


@pytest.mark.parametrize("speed", [s for s in SPEEDS if s is not None])
def test_ticking_once_a_second_at_rest_gives_the_run_of_twenty_ticks_a_second(speed):
    """A key, a rest, another key: the same times, poses and distances either way, when the
    seldom-ticking station runs what it owes before each command (as the app does)."""
    keys = ((0.0, "w"), (1.0, "space"), (4.0, "d"), (4.6, "space"), (9.0, "w"))

    def drive(rest_tick: float) -> list[tuple]:
        s = station(noise="low")
        s.pacer.speed = speed
        return _play(s, keys, 10.0, rest_tick)

    assert drive(1.0) == drive(0.05)


def test_a_long_rest_tick_keeps_all_the_time_it_owes():
    s = station()
    s.advance(1.0)  # the pacer's default drops what is owed beyond a quarter second
    assert s.session.world.time == pytest.approx(0.25, abs=1 / 60)
    s.advance(1.0, lag=1.25)
    assert s.session.world.time == pytest.approx(1.25, abs=1 / 60)


def _pressed_into_a_wall() -> LabStation:
    """A station whose robot drove into a wall and was stopped there."""
    s = station()
    s.key("w")
    for _ in range(400):  # 20 s at most: the start's corridor ends in a wall
        s.advance(0.05)
        if s.session.world.in_contact:
            break
    assert s.session.world.in_contact
    s.advance(0.5)  # pressed on into it
    s.key("space")
    return s


def test_a_robot_stopped_against_a_wall_rests_while_the_solver_eases_it_off():
    s = _pressed_into_a_wall()
    w = s.session.world
    rested = None
    for step in range(1, 601):  # 10 s
        s.step(1)
        if rested is None and s.at_rest:
            rested = step, w.pose
            assert not s.idle  # time still moves the robot: a dialog does not hold it
        if w.still:
            break
    assert w.still and rested is not None
    first, pose = rested
    # at rest within 3 s, well before the creep ends, and what was left of it is invisible
    assert first <= 180 < step
    assert abs(w.pose.x - pose.x) + abs(w.pose.y - pose.y) < 1e-8 * w.cell


@pytest.mark.parametrize("rest_tick", [0.5, 4.0])
def test_a_rest_against_a_wall_gives_the_run_of_twenty_ticks_a_second(rest_tick):
    """Stopped against a wall, left there while the solver eases the robot off it, then
    driven away: the same times, poses, readings, odometry and run whether the rest is ticked
    at 20 Hz or seldom."""
    keys = ((8.0, "s"), (8.7, "space"), (12.0, "d"), (12.5, "w"))

    def drive(rest: float) -> tuple[list[tuple], object]:
        s = _pressed_into_a_wall()
        return _play(s, keys, 15.0, rest), s.run_so_far()

    assert drive(rest_tick) == drive(0.05)
