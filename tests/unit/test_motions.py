"""What each command asks the robot to do, named as the drive keys (for the labs' key checks)."""

import pytest

from workbench.control.manual import KEY_NAMES, KEY_PROGRAMS
from workbench.sim.commands import (
    MotorPower,
    MoveAtPower,
    Stop,
    TurnByDegrees,
    WheelPowers,
    motion_of,
)


@pytest.mark.parametrize(
    ("cmd", "motion"),
    [
        (MoveAtPower(0.5), "forward"),
        (MoveAtPower(-1), "backward"),
        (MoveAtPower(0), "stop"),
        (Stop(), "stop"),
        (TurnByDegrees(90), "right"),
        (TurnByDegrees(-45), "left"),
        (TurnByDegrees(0), None),
        (WheelPowers(0.4, 0.4), "forward"),
        (WheelPowers(-0.4, -0.4), "backward"),
        (WheelPowers(0, 0), "stop"),
        (WheelPowers(0.5, -0.5), "right"),
        (WheelPowers(-0.2, 0.6), "left"),
        (MotorPower("left", 1), None),
    ],
)
def test_each_command_is_named_by_the_motion_it_asks_for(cmd, motion):
    assert motion_of(cmd) == motion


@pytest.mark.parametrize("profile", sorted(KEY_PROGRAMS))
def test_every_profile_key_program_makes_the_motion_its_key_is_named_for(profile):
    for key, cmd in KEY_PROGRAMS[profile].items():
        assert motion_of(cmd) == KEY_NAMES[key], (profile, key, cmd)
