"""Each profile's geometry leaves the lab text's thresholds a clear margin in a corridor."""

import pytest

from workbench.sim.profiles import PROFILES


@pytest.mark.parametrize("name", sorted(PROFILES))
def test_a_centred_robot_is_a_fifth_of_a_block_or_more_from_seeing_an_opening(name):
    p = PROFILES[name]
    centred = p.centred_reading("right")
    opening = 1.5 * p.cell - p.sensor_offset("right")
    assert p.open_above - centred >= 0.2 * p.cell
    assert opening - p.open_above >= 0.2 * p.cell


@pytest.mark.parametrize("name", sorted(PROFILES))
def test_stopping_at_a_wall_and_turning_leaves_the_side_reading_as_far_from_open(name):
    p = PROFILES[name]
    # stopped at "front < blocked_below": the centre is blocked_below + front offset from the
    # wall; after a quarter turn that wall is beside the robot
    beside = p.blocked_below + p.sensor_offset("front") - p.sensor_offset("right")
    assert p.open_above - beside >= 0.2 * p.cell
    # and the robot stopped within a tenth of a block of the last block's centre
    assert abs(p.blocked_below + p.sensor_offset("front") - p.cell / 2) <= 0.1 * p.cell
