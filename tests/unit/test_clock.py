"""Real-time pacing: wall time becomes a whole number of fixed steps, nothing lost or raced."""

import pytest

from workbench.sim.clock import Pacer
from workbench.sim.mazefile import parse_maze
from workbench.sim.session import Session

ROOM = parse_maze("#######\n#.....#\n#..S..#\n#.....#\n#######\n")


def pacer(**kw):
    return Pacer(Session(ROOM, "erobotic", noise="off"), **kw)


def test_wall_time_becomes_whole_steps_and_the_remainder_carries():
    p = pacer()
    total = sum(p.advance(0.025) for _ in range(40))  # one second in uneven frames
    assert total == 60
    assert p.session.world.time == pytest.approx(1.0)


def test_speed_factor_multiplies_simulated_time():
    p = pacer(speed=4.0)
    for _ in range(20):
        p.advance(0.05)
    assert p.session.world.time == pytest.approx(4.0)


def test_paused_runs_nothing_and_single_step_runs_exactly():
    p = pacer(paused=True)
    assert p.advance(1.0) == 0
    p.single_step(7)
    assert p.session.world.time == pytest.approx(7 / 60)


def test_a_long_stall_is_not_raced_through():
    p = pacer()
    assert p.advance(30.0) == 15  # at most max_lag (0.25 s) is owed


def test_speed_cycle_matches_the_app_choices():
    p = pacer()
    assert [p.next_speed() for _ in range(5)] == [2.0, 4.0, 10.0, None, 1.0]


def test_max_speed_steps_until_the_frame_budget_is_spent():
    ticks = iter(range(1000))
    p = pacer(speed=None, clock=lambda: next(ticks) * 0.01, budget=0.05)
    assert p.advance(0.05) == 150  # 30 steps per clock reading, budget reached at the 5th
