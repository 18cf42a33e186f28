"""The short cuts of the simulation's step give exactly what the long way gives.

``World.step`` does most steps itself (driving straight on the step it last worked out,
standing, turning in place) instead of calling ``World._advance``, and the session skips the
turn count on ticks where nothing turned. Here runs are made twice, once as they are and once
with every step through ``_advance``, and their run records must be the same byte for byte and
their measures equal: a short cut that changed one floating-point operation would show in the
poses, readings and distances the records hold.
"""

from __future__ import annotations

import math
import random
from pathlib import Path

import pytest

from workbench.control.headless import AlgorithmPilot, RunSpec, run
from workbench.fsm.algorithms import load_algorithm
from workbench.fsm.machine import FsmController, bind_sensors
from workbench.program.pilot import ProgramPilot
from workbench.sim import world as world_module
from workbench.sim.commands import MotorPower, MoveAtPower, Stop, TurnByDegrees, WheelPowers
from workbench.sim.generate import generate
from workbench.sim.maze import Maze
from workbench.sim.mazeio import load_maze
from workbench.sim.metrics import TurnCounter
from workbench.sim.sensors import SensorSpec
from workbench.sim.session import Session
from workbench.sim.world import World


def every_step_through_advance(world: World) -> tuple[str, ...]:
    """World.step without its short cuts: the whole step (or the rest of a split one) by
    ``_advance``, as before there were any."""
    part = world._part
    world._part = 0.0
    return world._advance(world.dt - part, True)


RUNS = {
    "right-wall FSM with noise to the exit": RunSpec(
        "mazes/web.txt", AlgorithmPilot("right-wall"), seed=3, noise="realistic", max_time=150
    ),
    "wheel-power FSM (web-wall-following)": RunSpec(
        "mazes/web.txt", AlgorithmPilot("web-wall-following"), profile="web", max_time=150
    ),
    "FSM turning by degrees on the erobotic maze": RunSpec(
        "mazes/erobotic.txt", AlgorithmPilot("farthest-distance"), seed=2, max_time=150
    ),
    "program with Timers and a touch sensor, noise": RunSpec(
        "mazes/web.txt",
        ProgramPilot("programs/right-wall.viple"),
        profile="web",
        seed=1,
        noise="realistic",
        max_time=150,
    ),
    "program with keys (key presses between steps)": RunSpec(
        "mazes/web.txt",
        ProgramPilot("programs/web-wall-following.viple", keys="w@0.5 a@2 w@3"),
        profile="web",
        max_time=60,
    ),
}


@pytest.mark.parametrize("name", RUNS)
def test_a_run_is_the_same_with_and_without_the_short_cuts(name, tmp_path, monkeypatch):
    spec = RUNS[name]
    advanced = 0
    general_advance = World._advance

    def counted(world: World, dt: float, whole: bool) -> tuple[str, ...]:
        nonlocal advanced
        advanced += 1
        return general_advance(world, dt, whole)

    monkeypatch.setattr(World, "_advance", counted)
    fast = run(_recorded(spec, tmp_path / "fast.jsonl"))
    steps = round(fast.metrics["sim_time"] / spec.dt)
    assert steps - advanced > 200, "the short cuts were hardly taken: this test tests nothing"
    monkeypatch.setattr(World, "step", every_step_through_advance)
    slow = run(_recorded(spec, tmp_path / "slow.jsonl"))
    assert fast.metrics == slow.metrics
    assert (tmp_path / "fast.jsonl").read_bytes() == (tmp_path / "slow.jsonl").read_bytes()


def _recorded(spec: RunSpec, path: Path) -> RunSpec:
    return RunSpec(**{**spec.__dict__, "record": str(path)})


#: a room of 12 x 12 open blocks: room for long straight lines and arcs away from walls
ROOM = Maze(rows=("#" * 14, *("#" + "." * 12 + "#" for _ in range(12)), "#" * 14), start=(2, 6))
#: step -> command: straight, an arc, one wheel, a stop, a turn, backwards, straight again
COMMANDS = {
    0: MoveAtPower(0.5),
    200: WheelPowers(0.5, 0.45),
    420: MotorPower("left", 0.3),
    500: Stop(),
    530: TurnByDegrees(-135),
    700: MoveAtPower(-0.4),
    820: WheelPowers(0.7, 0.7),
    1100: MoveAtPower(1.0),
}


@pytest.mark.parametrize("noise", ["off", "realistic"])
def test_poses_step_by_step_are_the_same_with_and_without_the_short_cuts(noise, monkeypatch):
    """Commands of every kind given between steps in an open room, then on into a wall: every
    step's pose, time, events and odometry, not only the ticks a record shows. Without noise
    the robot drives straight (and cruises); with it, a motor imbalance makes every straight
    line an arc."""

    def trace() -> list[tuple]:
        world = World(ROOM, "web", None, noise, 5, 1 / 60)
        out: list[tuple] = []
        for n in range(1600):
            if n in COMMANDS:
                world.apply(COMMANDS[n])
            events = world.step()
            out.append((world.pose, world.time, events, world.odometry, world.still))
            if n % 3 == 0:
                out.append(tuple(world.read_sensors().items()))
        return out

    advanced = 0
    general_advance = World._advance

    def counted(world: World, dt: float, whole: bool) -> tuple[str, ...]:
        nonlocal advanced
        advanced += 1
        return general_advance(world, dt, whole)

    monkeypatch.setattr(World, "_advance", counted)
    fast = trace()
    assert advanced < 800, "the short cuts were hardly taken: this test tests nothing"
    monkeypatch.setattr(World, "step", every_step_through_advance)
    assert trace() == fast


def test_the_turn_count_skipped_on_still_ticks_counts_as_an_update_on_every_tick():
    maze = load_maze("mazes/erobotic.txt")
    sensors = [SensorSpec("distance", p, m) for p, m in ((1, "front"), (2, "right"), (3, "left"))]
    definition = load_algorithm("farthest-distance")
    session = Session(maze, "erobotic", sensors, "realistic", seed=4)
    controller = FsmController(definition, {}, "erobotic")
    session.attach(controller, bind_sensors(definition, sensors, "erobotic"), "fsm")
    counter = TurnCounter()
    last_angle, last_time = session.world.angle, 0.0
    for n in range(1, 12_000):
        session.step()
        if n % session.every == 0:
            angle, t = session.world.angle, session.world.time
            counter.update(math.degrees(angle - last_angle), t - last_time)
            last_angle, last_time = angle, t
            assert session.metrics().turns == counter.current()
    assert counter.current() > 5  # it turned: the count was tested


def _contacts_of_all_nine(world: World, x: float, y: float) -> list[tuple[float, float]]:
    """What World._wall_contacts found before it kept a list of the walls near each side: each
    of the nine blocks around the robot, measured."""
    cell = world.cell
    bx, by = int(x * world._inv_cell), int(y * world._inv_cell)
    reach = world._touch_reach
    fx, fy = x - bx * cell, y - by * cell
    if reach < fx < cell - reach and reach < fy < cell - reach:
        return []
    found = []
    for j in (by - 1, by, by + 1):
        y0 = j * cell
        y1 = y0 + cell
        ny = y0 - y if y < y0 else y1 - y if y > y1 else 0.0
        for i in (bx - 1, bx, bx + 1):
            if world._solid[(j + 1) * world._wp + 1 + i]:
                x0 = i * cell
                x1 = x0 + cell
                nx = x0 - x if x < x0 else x1 - x if x > x1 else 0.0
                if nx * nx + ny * ny <= reach**2:
                    found.append((nx, ny))
    return found


@pytest.mark.parametrize("profile", ["web", "unity"])
def test_the_walls_in_touch_reach_are_those_a_search_of_all_nine_blocks_finds(profile):
    """Random places on the floor, and places a hair either side of the touch reach from a
    block's sides, where rounding would show first."""
    maze = load_maze("mazes/web.txt")
    world = World(maze, profile)
    cell, reach = world.cell, world._touch_reach
    rng = random.Random(7)
    floor = [(i, j) for j, row in enumerate(maze.rows) for i, ch in enumerate(row) if ch != "#"]
    offsets = [reach + d for d in (-1e-9, -1e-12, 0.0, 1e-12, 1e-9)]
    offsets += [cell - o for o in offsets]
    for n in range(20_000):
        i, j = rng.choice(floor)
        fx = rng.choice(offsets) if n % 3 == 0 else rng.uniform(0.0, cell)
        fy = rng.choice(offsets) if n % 5 == 0 else rng.uniform(0.0, cell)
        x, y = i * cell + fx, j * cell + fy
        world._x, world._y = x, y
        assert world._wall_contacts() == _contacts_of_all_nine(world, x, y), (x, y)


def _pymunk_steps_counted(monkeypatch) -> list[int]:
    """Count the steps pymunk takes from now on (one counter: the list's only item)."""
    counter = [0]
    space_step = world_module._space_step

    def counted(space: object, dt: float) -> None:
        counter[0] += 1
        space_step(space, dt)

    monkeypatch.setattr(world_module, "_space_step", counted)
    return counter


def _pymunk_takes_every_step_out_of_the_free_box(monkeypatch) -> None:
    # a joint that always holds an impulse: no step is found to be pymunk's free motion
    monkeypatch.setattr(world_module, "_get_impulse", lambda constraint: 1.0)


@pytest.mark.parametrize("name", RUNS)
def test_a_run_is_the_same_when_pymunk_takes_every_step_out_of_the_free_box(
    name, tmp_path, monkeypatch
):
    """Out of the free box, a step pymunk would take exactly as free motion (no wall within
    the box's clearance, both bodies moving alike, no joint impulse held, no contact
    remembered) is taken without pymunk: letting pymunk take every such step gives the same
    record byte for byte."""
    spec = RUNS[name]
    stepped = _pymunk_steps_counted(monkeypatch)
    fast = run(_recorded(spec, tmp_path / "fast.jsonl"))
    fast_steps, stepped[0] = stepped[0], 0
    _pymunk_takes_every_step_out_of_the_free_box(monkeypatch)
    slow = run(_recorded(spec, tmp_path / "slow.jsonl"))
    assert fast.metrics == slow.metrics
    assert (tmp_path / "fast.jsonl").read_bytes() == (tmp_path / "slow.jsonl").read_bytes()
    assert stepped[0] >= fast_steps


@pytest.mark.parametrize("profile", ["erobotic", "web", "unity"])
def test_poses_along_corridors_are_the_same_when_pymunk_takes_every_step(profile, monkeypatch):
    """Right-wall following through a perfect maze, past the corners of the walls beside the
    corridors (out of the free box, within reach of no wall): every step's pose, events and
    odometry, with the short cut and without it; and the short cut was taken."""
    maze = generate(8, 8, seed=4, style="perfect", exit="none")
    definition = load_algorithm("right-wall")
    sensors = [SensorSpec("distance", 1, "front"), SensorSpec("distance", 2, "right")]

    def trace() -> list[tuple]:
        session = Session(maze, profile, sensors, "off", seed=0)
        controller = FsmController(definition, {}, profile)
        session.attach(controller, bind_sensors(definition, sensors, profile), "fsm")
        out: list[tuple] = []
        for _ in range(4000):
            events = session.step()
            out.append((session.world.pose, events, session.world.odometry))
        return out

    stepped = _pymunk_steps_counted(monkeypatch)
    fast = trace()
    fast_steps, stepped[0] = stepped[0], 0
    _pymunk_takes_every_step_out_of_the_free_box(monkeypatch)
    assert trace() == fast
    assert stepped[0] > fast_steps + 100, "the short cut was hardly taken: this tests nothing"
