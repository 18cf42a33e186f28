"""Simulation fidelity: does the simulator teach the lessons the course means it to?

Measured over seeds, in one run, and printed:
  0. heading drift of a robot told to drive straight, per noise level and profile (200 seeds),
     beside the low level as it was before its retune ("old low": 0.02 % wheel imbalance,
     0.1 % turn error);
  1. wall followers on generated braid mazes (16 x 16 cells, boundary exit, 10 seeds): how many
     get out, for right-wall following and for left-wall following (right-wall following on the
     mirror image of the maze, which is what a left-hand rule does on the maze itself);
  2. wall following on the unity profile at its default noise, perfect mazes, 10 seeds: right
     and left wall on 8 x 8 and 16 x 16 cells, self-adjusting right wall on 16 x 16: false
     openings (pre-turn entries where the block beside the robot is wall), collisions, time,
     turning and exits, now beside the old low noise and the old sensor geometry (every sensor
     on the robot's edge, 0.18 from its centre, reading 0.82 in the middle of a corridor);
  3. the ranking mazes (mazes/rank-*.txt) under their own profile's default noise, 10 seeds: in
     how many seeds each shows the ranking it is meant to show;
  4. touch contacts: the Web wall-following program on web.txt, noise off and default, with
     intended touches counted apart from collisions;
  5. each noise level on 16 x 16 unity mazes: the plain followers against the self-adjusting one.

Every wall-following run gets the time limit `workbench run` gives its maze by default.

Targets: 10/10 braid mazes per follower; at unity's default noise, plain right- and left-wall
following get out of >= 9 of 10 mazes of either size with false openings under 5 % and under
one collision a run, and the self-adjusting follower stays as good as before; at realistic
noise the plain followers collide and turn far more while the self-adjusting one does not; each
ranking held in >= 8 of 10 seeds; web wall following touches the wall on purpose but does not
collide.

Usage: python bench/fidelity.py [--seeds N] [--only PART]
"""

from __future__ import annotations

import argparse
import math
import statistics
import sys
from dataclasses import replace
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from workbench.control.headless import default_max_time  # noqa: E402
from workbench.fsm.algorithms import load_algorithm  # noqa: E402
from workbench.fsm.machine import FsmController, bind_sensors, preset_sensors  # noqa: E402
from workbench.sim.commands import MoveAtPower, WheelPowers  # noqa: E402
from workbench.sim.driver import Driver  # noqa: E402
from workbench.sim.generate import generate  # noqa: E402
from workbench.sim.maze import Maze  # noqa: E402
from workbench.sim.mazeio import load_maze  # noqa: E402
from workbench.sim.noise import NoiseSettings, noise_settings  # noqa: E402
from workbench.sim.profiles import NOISE_LEVELS, UNITY, Profile, get_profile  # noqa: E402
from workbench.sim.session import Session  # noqa: E402
from workbench.sim.world import EXIT, World  # noqa: E402

MAZES = ROOT / "mazes"

#: the unity profile before the fidelity retune: every sensor on the robot's edge
UNITY_BEFORE = replace(UNITY, robot_radius=0.18, sensor_offsets=(0.18, 0.18, 0.18, 0.18))

#: the low noise level before its retune (per-wheel gain and per-turn standard deviations): a
#: robot told to drive straight turned 0.5 degrees a minute on unity, some 20 degrees over a
#: 16 x 16 maze
OLD_LOW = {"motor_imbalance": 0.0002, "turn_error": 0.001}


def noise_for(level: str, profile: Profile) -> NoiseSettings:
    """A noise level's settings for a profile; "old low" is the low level before its retune."""
    if level == "old low":
        return noise_settings("low", profile, **OLD_LOW)
    return noise_settings(level, profile)


#: each ranking maze's intended winner and the algorithms its description ranks it against
RANKINGS = {
    "rank-wall-wins.txt": (
        "right-wall",
        ("farthest-distance", "one-distance-first", "two-distance-local-best"),
    ),
    "rank-local-best-wins.txt": (
        "two-distance-local-best",
        ("right-wall", "farthest-distance", "one-distance-first", "first-working-solution"),
    ),
}


def session_for(
    maze: Maze,
    algorithm: str,
    profile: Profile,
    seed: int,
    noise: NoiseSettings | str | None = None,
    params: dict[str, float] | None = None,
) -> tuple[Session, FsmController]:
    definition = load_algorithm(algorithm)
    sensors = preset_sensors(definition, profile.name)
    binding = bind_sensors(definition, sensors, profile.name)
    controller = FsmController(definition, params, profile.name)
    session = Session(maze, profile, sensors, noise or profile.noise, seed)  # type: ignore[arg-type]
    session.attach(controller, binding, Driver.algorithm(definition.name))
    return session, controller


def run(
    maze: Maze,
    algorithm: str,
    profile: Profile,
    seed: int,
    max_time: float,
    noise: NoiseSettings | str | None = None,
    watch: str | None = None,
    params: dict[str, float] | None = None,
) -> tuple[dict, int, int]:
    """Metrics of one run, and (entries into ``watch``, of which the right side was wall)."""
    session, controller = session_for(maze, algorithm, profile, seed, noise, params)
    world = session.world
    entries = false = 0
    previous = controller.state
    for _ in range(math.ceil(max_time / world.dt)):
        events = session.step()
        state = controller.state
        if state != previous:
            if state == watch:
                entries += 1
                false += not _right_block_open(world)
            previous = state
        if EXIT in events:
            break
    session.settle()
    return session.metrics().as_dict(), entries, false


def _right_block_open(world) -> bool:
    """Whether the block one cell to the robot's right (heading snapped to the grid) is floor.

    The robot sees an opening when its centre is level with the opening's corner, so the
    block beside a point a hair ahead of the centre is the one the sensor looked into.
    """
    x, y, heading = world.pose
    quarter = round(heading / 90.0) % 4
    fx, fy = ((1, 0), (0, 1), (-1, 0), (0, -1))[quarter]  # east, south, west, north
    rx, ry = -fy, fx
    bx = math.floor(x / world.cell + 0.02 * fx + rx)
    by = math.floor(y / world.cell + 0.02 * fy + ry)
    return world.maze.in_bounds(bx, by) and not world.maze.is_wall(bx, by)


def braid_success(seeds: int) -> None:
    print(f"1. wall followers on generated braid mazes (16x16 cells, {seeds} seeds)")
    out = {"right wall": 0, "left wall": 0}
    for seed in range(seeds):
        maze = generate(16, 16, seed, "braid")
        for name, m in (("right wall", maze), ("left wall", maze.mirrored())):
            metrics, _, _ = run(m, "right-wall", UNITY, seed, 3000.0)
            out[name] += metrics["reached_exit"]
    for name, got in out.items():
        print(f"   {name:<12} out of {got}/{seeds} mazes")


def _follow(
    size: int, seed: int, algorithm: str, hand: str, profile: Profile, noise: NoiseSettings | str
) -> tuple[dict, int, int]:
    """One wall-following run on a generated perfect maze, with the time a run gets by default.

    Left-wall following is right-wall following on the mirror image of the maze."""
    maze = generate(size, size, seed)
    if hand == "left":
        maze = maze.mirrored()
    params = None
    if algorithm == "self-adjusting-wall":
        # the self-adjusting follower keeps the centred side reading of its geometry
        params = {"base_distance": profile.centred_reading("right")}
    limit = default_max_time(maze, profile, profile.cell)
    return run(maze, algorithm, profile, seed, limit, noise, "BesideOpening", params)


def _follow_line(
    seeds: int,
    size: int,
    algorithm: str,
    hand: str,
    profile: Profile,
    noise: NoiseSettings | str,
) -> str:
    entries = false = out = 0
    collisions, times, turning = [], [], []
    for seed in range(seeds):
        metrics, e, f = _follow(size, seed, algorithm, hand, profile, noise)
        entries += e
        false += f
        out += metrics["reached_exit"]
        collisions.append(metrics["collisions"])
        times.append(metrics["sim_time"])
        turning.append(metrics["turn_degrees"])
    share = 100 * false / entries if entries else 0.0
    return (
        f"{false}/{entries} false openings ({share:.0f} %), "
        f"{statistics.fmean(collisions):.1f} collisions/run, "
        f"{statistics.fmean(times):.0f} s, {statistics.fmean(turning):.0f} deg, out {out}/{seeds}"
    )


def _name(algorithm: str, hand: str) -> str:
    return f"{hand} wall" if algorithm == "right-wall" else algorithm


def unity_margin(seeds: int) -> None:
    print(
        f"2. wall following, unity profile, default noise, perfect mazes ({seeds} seeds; "
        "left wall = right wall on the mirror image; each run gets the default time limit)"
    )
    print(
        "   'edge sensors' = every sensor on the robot's edge (centred side reading "
        f"{UNITY_BEFORE.centred_reading('right'):.2f}); 'old low' = the low noise level before "
        f"its retune (imbalance {OLD_LOW['motor_imbalance']:.2%}, turn error "
        f"{OLD_LOW['turn_error']:.1%})"
    )
    variants = {
        "edge sensors, old low": (UNITY_BEFORE, "old low"),
        "old low": (UNITY, "old low"),
        "now": (UNITY, UNITY.noise),
    }
    cases = [
        (8, "right-wall", "right", tuple(variants)),
        (8, "right-wall", "left", ("old low", "now")),
        (16, "right-wall", "right", tuple(variants)),
        (16, "right-wall", "left", ("old low", "now")),
        (16, "self-adjusting-wall", "right", ("old low", "now")),
    ]
    for size, algorithm, hand, labels in cases:
        for label in labels:
            profile, noise = variants[label]
            line = _follow_line(seeds, size, algorithm, hand, profile, noise_for(noise, profile))
            case = f"{_name(algorithm, hand)} {size}x{size}"
            print(f"   {case:<25} {label:<21} {line}")


def noise_levels(seeds: int) -> None:
    print(
        f"5. each noise level, unity profile, 16x16 perfect mazes ({seeds} seeds): the plain "
        "followers against the self-adjusting one"
    )
    for level in NOISE_LEVELS:
        for algorithm, hand in (
            ("right-wall", "right"),
            ("right-wall", "left"),
            ("self-adjusting-wall", "right"),
        ):
            line = _follow_line(seeds, 16, algorithm, hand, UNITY, level)
            print(f"   {level:<9} {_name(algorithm, hand):<19} {line}")


def drift(seeds: int) -> None:
    """How fast each level's motor imbalance turns a robot told to drive straight."""
    seeds = max(seeds, 200)
    print(f"0. heading drift driving straight, degrees per minute ({seeds} seeds: mean, 90 %)")
    drives = {"unity": MoveAtPower(1.0), "web": WheelPowers(0.5, 0.5), "erobotic": MoveAtPower(1.0)}
    maze = generate(4, 4, 0)
    levels = ["old low", *(level for level in NOISE_LEVELS if level != "off")]
    for level in levels:
        cells = []
        for name, command in drives.items():
            rates = []
            for seed in range(seeds):
                world = World(maze, name, noise=noise_for(level, get_profile(name)), seed=seed)
                before = world.angle
                world.apply(command)
                world.run(1.0)
                rates.append(abs(math.degrees(world.angle - before)) * 60.0)
            rates.sort()
            cells.append(
                f"{name} {statistics.fmean(rates):.2f} (< {rates[int(0.9 * seeds) - 1]:.2f})"
            )
        print(f"   {level:<9} " + ", ".join(cells))


def rankings(seeds: int) -> None:
    print(f"3. ranking mazes under their own profile's default noise ({seeds} seeds)")
    for name, (winner, others) in RANKINGS.items():
        maze = load_maze(MAZES / name)
        profile = get_profile(maze.profile or "unity")
        limit = default_max_time(maze, profile, profile.cell)
        held = 0
        for seed in range(seeds):
            mine = run(maze, winner, profile, seed, limit)[0]
            rest = [run(maze, a, profile, seed, limit)[0] for a in others]
            held += ranking_holds(mine, rest)
        print(f"   {name:<26} {winner} wins in {held}/{seeds} seeds")


def ranking_holds(winner: dict, others: list[dict]) -> bool:
    """The winner gets out, travelling less and turning less than every other that gets out."""
    return winner["reached_exit"] and all(
        winner["distance_cells"] < r["distance_cells"]
        and winner["turn_degrees"] < r["turn_degrees"]
        for r in others
        if r["reached_exit"]
    )


def touches(seeds: int) -> None:
    print(f"4. web wall following: collisions and intended touches ({seeds} seeds)")
    web = get_profile("web")
    cases = [("web.txt", lambda seed: load_maze(MAZES / "web.txt"))]
    cases.append(("8x8 perfect", lambda seed: generate(8, 8, seed)))
    for name, make in cases:
        for noise in ("off", web.noise):
            hits, taps = [], []
            for seed in range(seeds):
                maze = make(seed)
                limit = default_max_time(maze, web, web.cell)
                metrics, _, _ = run(maze, "web-wall-following", web, seed, limit, noise=noise)
                hits.append(metrics["collisions"])
                taps.append(metrics["touches"])
            print(
                f"   {name:<12} noise {noise:<4} collisions {min(hits)}-{max(hits)} "
                f"(mean {statistics.fmean(hits):.1f}), touches {min(taps)}-{max(taps)} "
                f"(mean {statistics.fmean(taps):.1f})"
            )


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, default=10)
    parser.add_argument("--only", choices=("drift", "braid", "unity", "rank", "touch", "levels"))
    args = parser.parse_args()
    parts = {
        "drift": drift,
        "braid": braid_success,
        "unity": unity_margin,
        "rank": rankings,
        "touch": touches,
        "levels": noise_levels,
    }
    for key, part in parts.items():
        if args.only in (None, key):
            part(args.seeds)
    return 0


if __name__ == "__main__":
    sys.exit(main())
