"""The values a lab's text points to complete its starter FSM on the lab's mazes.

The Unity wall-following exercise sends the students to the built-in right-wall's Unity values
for the four FILL IN parameters. With them the starter must get out of each maze of the
exercise at the profile's own (default) noise, whatever the seed, and out of the eRobotic maze
without touching a wall, as its objective asks; the objective itself is not weakened.
"""

from __future__ import annotations

import pytest

from workbench.control.headless import AlgorithmPilot, RunSpec
from workbench.fsm.algorithms import load_algorithm
from workbench.fsm.machine import resolve_params
from workbench.labs.model import load_labs
from workbench.tui.widgets.param_editor import fill_in_hint

LABS = {lab.id: lab for lab in load_labs()}
EXERCISE = LABS["unity-simulator"].exercise("wall-following")
STARTER = EXERCISE.setup.controller.value
SEEDS = range(5)


def right_wall_values() -> tuple[str, ...]:
    """The FILL IN parameters of the starter, at the built-in right-wall's Unity values."""
    starter = load_algorithm(STARTER)
    builtin = resolve_params(load_algorithm("right-wall"), "unity")
    blanks = [p.name for p in starter.parameters if fill_in_hint(p) is not None]
    assert blanks == ["open_right", "front_blocked", "right_turn", "left_turn"]
    turns = {"right_turn": 90, "left_turn": -90}  # the built-in's quarter turns
    return tuple(f"{name}={builtin.get(name, turns.get(name))}" for name in blanks)


def test_the_lab_text_points_to_the_built_in_right_wall():
    assert "right-wall" in EXERCISE.instructions
    assert right_wall_values() == (
        "open_right=1.0",
        "front_blocked=0.9",
        "right_turn=90",
        "left_turn=-90",
    )


@pytest.mark.parametrize("seed", SEEDS)
def test_those_values_get_out_of_every_maze_of_the_exercise(seed):
    exits = [o for o in EXERCISE.objectives if o.kind == "exit"]
    assert len(exits) >= 2
    for objective in exits:
        result = RunSpec(
            maze=str(objective.maze.path),
            pilot=AlgorithmPilot(STARTER, right_wall_values()),
            profile="unity",
            seed=seed,
        ).execute()
        assert result["reached_exit"], (objective.text, seed)
        if objective.max_collisions is not None:
            assert result["collisions"] <= objective.max_collisions, (objective.text, seed)
