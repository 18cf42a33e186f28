"""Simulation speed: the full session pipeline against a pure-geometry ceiling, in one run.

Prints simulated seconds per wall second for
  1. the full pipeline: Session.step() with pymunk physics, grid ray sensors and the right-wall
     FSM at the control rate (recording off);
  2. a reference loop with the same controller, sensors and control rate but no physics:
     kinematic integration of the pose and the same grid ray stepping (the ceiling);
and their ratio; then the speed-up of `eval --jobs 2` over `--jobs 1`.

Targets: pipeline >= 1000x real time, >= 0.8 of the reference, eval speed-up >= 1.7 on 2 cores.
"""

from __future__ import annotations

import math
import os
import tempfile
import time

from workbench.control.evaluate import evaluate
from workbench.fsm.algorithms import load_algorithm
from workbench.fsm.machine import FsmController, bind_sensors
from workbench.sim.commands import MoveAtPower, Stop, TurnByDegrees, WheelPowers
from workbench.sim.generate import generate
from workbench.sim.mazefile import write_maze
from workbench.sim.profiles import get_profile
from workbench.sim.sensors import MOUNTS, SensorSpec
from workbench.sim.session import Session
from workbench.sim.world import HEADING_ANGLES, _march

SIM_SECONDS = 1500.0
#: pipeline and reference loops each, taken in turn (the best of each counts)
ROUNDS = 5
DT = 1 / 60
SENSORS = [
    SensorSpec("distance", 1, "front"),
    SensorSpec("distance", 2, "left"),
    SensorSpec("distance", 3, "right"),
]


def pipeline(maze, profile: str) -> tuple[float, dict]:
    definition = load_algorithm("right-wall")
    session = Session(maze, profile, SENSORS, "off", seed=0, dt=DT)
    session.attach(
        FsmController(definition, {}, profile), bind_sensors(definition, SENSORS, profile), "fsm"
    )
    steps = round(SIM_SECONDS / DT)
    t0 = time.perf_counter()
    for _ in range(steps):
        session.step()
    wall = time.perf_counter() - t0
    return SIM_SECONDS / wall, session.metrics().as_dict()


def reference(maze, profile_name: str) -> tuple[float, float]:
    """Same controller and sensors; pose integrated kinematically, no collisions."""
    profile = get_profile(profile_name)
    definition = load_algorithm("right-wall")
    controller = FsmController(definition, {}, profile_name)
    binding = bind_sensors(definition, SENSORS, profile_name)
    names = {port: name for name, port in binding.items()}
    cell = maze.cell or profile.cell
    inv = 1.0 / cell
    wp = maze.width + 2
    solid = bytearray([1]) * (wp * (maze.height + 2))
    for y, row in enumerate(maze.rows):
        for x, ch in enumerate(row):
            if ch != "#":
                solid[(y + 1) * wp + x + 1] = 0
    solid = bytes(solid)
    tmax = profile.sensor_range / cell
    plan = [(s.port, MOUNTS.index(s.mount), profile.sensor_offset(s.mount)) for s in SENSORS]
    x = (maze.start[0] + 0.5) * cell
    y = (maze.start[1] + 0.5) * cell
    a = math.radians(HEADING_ANGLES[maze.heading])
    v = w = 0.0
    target = None
    rate = math.radians(profile.turn_rate)
    every = round(1 / (DT * 20))
    events: list[str] = []
    distance = 0.0

    def apply(cmd) -> None:
        nonlocal v, w, target
        target = None
        if isinstance(cmd, MoveAtPower):
            v = math.copysign(profile.move_speed, cmd.power) if cmd.power else 0.0
            w = 0.0
        elif isinstance(cmd, WheelPowers):
            left = cmd.left * profile.max_wheel_speed
            right = cmd.right * profile.max_wheel_speed
            v, w = 0.5 * (left + right), (left - right) / profile.track_width
        elif isinstance(cmd, TurnByDegrees):
            v, w = 0.0, 0.0
            target = a + math.radians(cmd.degrees)
        elif isinstance(cmd, Stop):
            v = w = 0.0

    started = False
    steps = round(SIM_SECONDS / DT)
    t0 = time.perf_counter()
    for step in range(1, steps + 1):
        if target is not None:
            w = max(-rate, min(rate, (target - a) / DT))
        nx = x + v * math.cos(a) * DT
        ny = y + v * math.sin(a) * DT
        if not solid[(int(ny * inv) + 1) * wp + int(nx * inv) + 1]:
            distance += math.hypot(nx - x, ny - y)
            x, y = nx, ny
        a += w * DT
        if target is not None and abs(target - a) < 1e-7:
            target = None
            w = 0.0
            events.append("turn_done")
        if step % every == 0:
            c, s = math.cos(a), math.sin(a)
            dirs = ((c, s), (-s, c), (-c, -s), (s, -c))
            readings = {}
            for port, mount, offset in plan:
                dx, dy = dirs[mount]
                t = _march(solid, wp, (x + offset * dx) * inv + 1.0, (y + offset * dy) * inv + 1.0,
                           dx, dy, tmax)  # fmt: skip
                readings[port] = profile.no_echo if t < 0 else t * cell
            if not started:
                started = True
                commands = controller.start(step * DT)
            else:
                named = {name: readings[port] for port, name in names.items()}
                commands = controller.tick(step * DT, named, frozenset(events))
            for cmd in commands:
                apply(cmd)
            events = []
    wall = time.perf_counter() - t0
    return SIM_SECONDS / wall, distance / cell


def eval_speedup(maze_path: str) -> tuple[float, float, float]:
    kwargs = dict(seeds=16, profile="erobotic", noise="realistic", max_time=600.0)
    mazes = [maze_path]
    algorithms = ["right-wall", "farthest-distance"]
    t0 = time.perf_counter()
    evaluate(mazes, algorithms, jobs=1, **kwargs)
    one = time.perf_counter() - t0
    t0 = time.perf_counter()
    evaluate(mazes, algorithms, jobs=2, **kwargs)
    two = time.perf_counter() - t0
    return one, two, one / two


def main() -> None:
    maze = generate(16, 16, seed=7, style="perfect", exit="none")
    profile = "erobotic"
    print(f"maze: {maze.name} ({maze.width}x{maze.height} blocks), right-wall, 3 distance sensors,")
    print(f"dt 1/60, noise off, profile {profile}, {SIM_SECONDS:g} simulated seconds per loop")
    # interleaved, best of ROUNDS each, so load from other processes hits both alike
    fulls, refs = [], []
    for _ in range(ROUNDS):
        full, metrics = pipeline(maze, profile)
        ref, ref_cells = reference(maze, profile)
        fulls.append(full)
        refs.append(ref)
    full, ref = max(fulls), max(refs)
    print(f"full pipeline (Session.step):  {full:10.0f} x real time "
          f"({metrics['distance_cells']:.0f} blocks driven)")  # fmt: skip
    print(f"reference (no physics):        {ref:10.0f} x real time ({ref_cells:.0f} blocks driven)")
    ratio = full / ref
    print(f"pipeline / reference:          {ratio:10.2f}   "
          f"(target >= 0.80: {'met' if ratio >= 0.8 else 'NOT met'})")  # fmt: skip
    print(f"pipeline vs real time target:  {'met' if full >= 1000 else 'NOT met'} (>= 1000x)")
    with tempfile.TemporaryDirectory() as tmp:
        path = os.path.join(tmp, "eval-maze.txt")
        write_maze(path, generate(16, 16, seed=3, style="braid", exit="center"))
        one, two, speedup = eval_speedup(path)
    print(f"eval --jobs 1: {one:.2f} s, --jobs 2: {two:.2f} s, speed-up {speedup:.2f} "
          f"(target >= 1.7 on 2 cores; this machine has {os.cpu_count()} cores)")  # fmt: skip


if __name__ == "__main__":
    main()
