"""The simulator teaches the course's lessons, not artefacts of its geometry (measured over
seeds; `bench/fidelity.py` gives the full figures)."""

import pytest

from workbench.control.algorithms import load_algorithm
from workbench.control.fsm import FsmController, bind_sensors, preset_sensors
from workbench.control.headless import RunSpec, run
from workbench.sim.driver import Driver
from workbench.sim.generate import generate
from workbench.sim.session import Session


def follow_right_wall(maze, profile, seed, max_time=1500.0):
    definition = load_algorithm("right-wall")
    sensors = preset_sensors(definition, profile)
    session = Session(maze, profile, sensors, seed=seed)
    session.attach(
        FsmController(definition, None, profile),
        bind_sensors(definition, sensors, profile),
        Driver.algorithm("right-wall"),
    )
    return session.run(max_time)


@pytest.mark.parametrize("hand", ["right", "left"])
def test_wall_followers_get_out_of_every_generated_braid_maze(hand):
    for seed in range(5):
        maze = generate(8, 8, seed, "braid")
        # a left-hand rule on a maze is the right-hand rule on its mirror image
        metrics = follow_right_wall(maze if hand == "right" else maze.mirrored(), "unity", seed)
        assert metrics.reached_exit, f"seed {seed}: {hand} wall following did not get out"


RANKED = {
    "rank-local-best-wins": (
        "two-distance-local-best",
        ["right-wall", "farthest-distance", "one-distance-first", "first-working-solution"],
    ),
    "rank-wall-wins": (
        "right-wall",
        ["farthest-distance", "one-distance-first", "two-distance-local-best"],
    ),
}


@pytest.mark.parametrize("maze", sorted(RANKED))
def test_ranking_mazes_show_their_winner_under_their_own_profiles_default_noise(maze):
    winner, others = RANKED[maze]
    for seed in range(10):
        mine = run(RunSpec(maze=f"mazes/{maze}.txt", algorithm=winner, seed=seed)).as_dict()
        assert mine["reached_exit"], seed
        for other in others:
            theirs = run(RunSpec(maze=f"mazes/{maze}.txt", algorithm=other, seed=seed)).as_dict()
            if theirs["reached_exit"]:
                assert mine["distance_cells"] < theirs["distance_cells"], (seed, other)
                assert mine["turn_degrees"] < theirs["turn_degrees"], (seed, other)
