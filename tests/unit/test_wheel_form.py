"""Commands as a robot with only Robot Drive understands them: the stand-in client's default."""

from __future__ import annotations

import pytest

from tests.unit.test_world import angle_between, corridor
from workbench.sim.commands import MotorPower, MoveAtPower, Stop, TurnByDegrees, WheelPowers
from workbench.sim.profiles import PROFILES, get_profile
from workbench.sim.world import World
from workbench.viple.wheel_form import WheelDrive, spin_rate


@pytest.mark.parametrize("profile", list(PROFILES))
@pytest.mark.parametrize("degrees", [90.0, -90.0, 180.0, 15.0])
def test_a_turn_as_a_timed_spin_turns_the_robot_by_its_angle(profile, degrees):
    world = World(corridor(3), profile, noise="off")
    drive = WheelDrive(get_profile(profile))
    start = world.pose.heading
    spin = drive.powers(0.0, TurnByDegrees(degrees))
    assert spin.left == -spin.right and (spin.left > 0) == (degrees > 0)
    assert drive.spin_ends == pytest.approx(abs(degrees) / get_profile(profile).turn_rate)
    world.apply(spin)
    steps = round(drive.spin_ends / world.dt)
    for _ in range(steps):
        world.step()
    assert not drive.spin_over(drive.spin_ends - 0.01)
    assert drive.spin_over(drive.spin_ends) and not drive.spin_over(99.0)  # once
    world.apply(WheelPowers(0.0, 0.0))
    world.run(0.5)
    # as far as Turn by Degree turns it, give or take what one physics step turns
    one_step = spin_rate(get_profile(profile)) * world.dt
    turned = (world.pose.heading - start) % 360.0
    assert angle_between(turned, degrees % 360.0) <= one_step + 0.01


@pytest.mark.parametrize("profile", list(PROFILES))
def test_move_at_power_becomes_both_wheels_at_the_same_speed(profile):
    moved = []
    for command in (MoveAtPower(0.5), WheelDrive(get_profile(profile)).powers(0, MoveAtPower(0.5))):
        world = World(corridor(8), profile, noise="off")
        x0 = world.pose.x
        world.apply(command)
        world.run(0.5)
        moved.append(world.pose.x - x0)
    assert moved[1] == pytest.approx(moved[0], rel=1e-6) and moved[0] > 0


def test_one_motor_keeps_the_other_wheel_and_any_command_ends_a_spin():
    drive = WheelDrive(get_profile("web"))
    assert drive.powers(0.0, WheelPowers(0.3, 0.4)) == WheelPowers(0.3, 0.4)
    assert drive.powers(0.1, MotorPower("right", -0.2)) == WheelPowers(0.3, -0.2)
    assert drive.powers(0.2, MotorPower("left", 1.0)) == WheelPowers(1.0, -0.2)
    drive.powers(0.3, TurnByDegrees(-45))
    assert drive.spin_ends is not None
    assert drive.powers(0.4, Stop()) == WheelPowers(0.0, 0.0)
    assert drive.spin_ends is None and not drive.spin_over(10.0)
    assert drive.powers(0.5, TurnByDegrees(0)) == WheelPowers(0.0, 0.0)
    assert drive.spin_ends is None
