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


@pytest.mark.parametrize("speed", [s for s in SPEEDS if s is not None])
def test_ticking_once_a_second_at_rest_gives_the_run_of_twenty_ticks_a_second(speed):
    """A key, a rest, another key: the same times, poses and distances either way, when the
    seldom-ticking station runs what it owes before each command (as the app does)."""

    def drive(rest_tick: float) -> list[tuple]:
        s = station(noise="low")
        s.pacer.speed = speed
        # a clock that never moves: the frame budget (wall time) never cuts a tick short,
        # so a loaded machine runs the same steps as a quiet one
        s.pacer.clock = lambda: 0.0
        seen = []
        wall = 0.0

        def tick(seconds: float, lag: float | None = None) -> None:
            nonlocal wall
            s.advance(seconds, lag)
            wall += seconds

        def keep_up(until: float) -> None:
            # the app: 20 Hz while things move, one tick per rest_tick while at rest
            while wall < until - 1e-9:
                if s.at_rest:
                    tick(min(rest_tick, until - wall), lag=rest_tick + s.pacer.max_lag)
                else:
                    tick(min(0.05, until - wall))

        for at, key in ((0.0, "w"), (1.0, "space"), (4.0, "d"), (4.6, "space"), (9.0, "w")):
            keep_up(at)
            s.key(key)
            w = s.session.world
            seen.append((key, round(w.time, 9), w.pose, dict(s.session.readings)))
        keep_up(10.0)
        w = s.session.world
        seen.append(("end", round(w.time, 9), w.pose, w.odometry))
        return seen

    assert drive(1.0) == drive(0.05)


def test_a_long_rest_tick_keeps_all_the_time_it_owes():
    s = station()
    s.advance(1.0)  # the pacer's default drops what is owed beyond a quarter second
    assert s.session.world.time == pytest.approx(0.25, abs=1 / 60)
    s.advance(1.0, lag=1.25)
    assert s.session.world.time == pytest.approx(1.25, abs=1 / 60)
