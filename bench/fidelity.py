"""Simulation fidelity: does the simulator teach the lessons the course means it to?

Measured over seeds, in one run, and printed:
  1. wall followers on generated braid mazes (16 x 16 cells, boundary exit, 10 seeds): how many
     get out, for right-wall following and for left-wall following (right-wall following on the
     mirror image of the maze, which is what a left-hand rule does on the maze itself);
  2. wall following on the unity profile at its default noise, perfect mazes, 10 seeds: right
     wall on 8 x 8 and 16 x 16 cells, self-adjusting right wall on 16 x 16: false openings
     (pre-turn entries where the block beside the robot is wall) and collisions per run, with
     the profile as it is and with the geometry it replaced (every sensor on the robot's edge,
     0.18 from its centre, reading 0.82 in the middle of a corridor);
  3. the ranking mazes (mazes/rank-*.txt) under their own profile's default noise, 10 seeds: in
     how many seeds each shows the ranking it is meant to show;
  4. touch contacts: the Web wall-following program on web.txt, noise off and default, with
     intended touches counted apart from collisions.

Targets: 10/10 braid mazes per follower; unity false openings near 0 on runs of lab length
(8 x 8) and no more collisions than the old geometry; on long runs (16 x 16, some 40 simulated
minutes) the plain follower's heading drifts with the motors' imbalance, which the self-adjusting
follower corrects; each ranking held in >= 8 of 10 seeds; web wall following touches the
wall on purpose but does not collide.

Usage: python bench/fidelity.py [--seeds N]
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

from workbench.control.algorithms import load_algorithm  # noqa: E402
from workbench.control.fsm import FsmController, bind_sensors, preset_sensors  # noqa: E402
from workbench.control.headless import default_max_time  # noqa: E402
from workbench.sim.driver import Driver  # noqa: E402
from workbench.sim.generate import generate  # noqa: E402
from workbench.sim.maze import Maze  # noqa: E402
from workbench.sim.mazeio import load_maze  # noqa: E402
from workbench.sim.profiles import UNITY, Profile, get_profile  # noqa: E402
from workbench.sim.session import Session  # noqa: E402
from workbench.sim.world import EXIT  # noqa: E402

MAZES = ROOT / "mazes"

#: the unity profile before the fidelity retune: every sensor on the robot's edge
UNITY_BEFORE = replace(UNITY, robot_radius=0.18, sensor_offsets=(0.18, 0.18, 0.18, 0.18))

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
    noise: str | None = None,
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
    noise: str | None = None,
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


def unity_margin(seeds: int) -> None:
    print(f"2. wall following, unity profile, default noise, perfect mazes ({seeds} seeds)")
    cases = [(8, "right-wall"), (16, "right-wall"), (16, "self-adjusting-wall")]
    for size, algorithm in cases:
        for label, profile in (("before", UNITY_BEFORE), ("after", UNITY)):
            # the self-adjusting follower keeps the centred side reading of its geometry
            params = {"base_distance": profile.centred_reading("right")}
            if algorithm == "right-wall":
                params = {}
            entries = false = out = 0
            collisions, times, turning = [], [], []
            for seed in range(seeds):
                maze = generate(size, size, seed)
                metrics, e, f = run(
                    maze, algorithm, profile, seed, 3000.0, watch="BesideOpening", params=params
                )
                entries += e
                false += f
                out += metrics["reached_exit"]
                collisions.append(metrics["collisions"])
                times.append(metrics["sim_time"])
                turning.append(metrics["turn_degrees"])
            side = profile.centred_reading("right")
            print(
                f"   {algorithm} {size}x{size} {label:<6} (centred side reading {side:.2f}): "
                f"{false}/{entries} false openings, "
                f"{statistics.fmean(collisions):.1f} collisions/run, "
                f"{statistics.fmean(times):.0f} s, {statistics.fmean(turning):.0f} deg, "
                f"out {out}/{seeds}"
            )


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
    parser.add_argument("--only", choices=("braid", "unity", "rank", "touch"))
    args = parser.parse_args()
    parts = {"braid": braid_success, "unity": unity_margin, "rank": rankings, "touch": touches}
    for key, part in parts.items():
        if args.only in (None, key):
            part(args.seeds)
    return 0


if __name__ == "__main__":
    sys.exit(main())
