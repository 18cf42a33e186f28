"""A lab rests on its mazes and starters as they were when it was loaded: a run on an easier
copy, or on the file changed on disk afterwards, meets no objective on the lab's maze."""

import shutil
from pathlib import Path

import pytest

from tests.stations import run_to_exit
from workbench.control.station import LabStation
from workbench.labs.checks import apply_setup, attempt_of, check_objective
from workbench.labs.model import LabFileError, load_lab
from workbench.sim.mazeio import load_maze

LAB = """\
lab: pinned
title: Pinned
exercises:
  - id: out
    title: Get out
    instructions: Get out.
    setup:
      profile: unity
      maze: lab-maze.txt
      sensors: [distance:1:right, distance:2:front]
      controller: {controller}
    objectives:
      - kind: exit
        text: right wall got out
        maze: lab-maze.txt
        driver: {driver}
"""
ORIGINAL = Path("mazes/rank-wall-wins.txt").read_text()
#: the same maze (same name) with the start moved next to the exit, facing it
EASIER = ORIGINAL.replace("#......E....#", "#.....>E....#").replace("#^#", "#.#")


def lab_in(tmp_path, controller="algorithm right-wall", driver="algorithm right-wall"):
    (tmp_path / "lab-maze.txt").write_text(ORIGINAL)
    shutil.copy("labs/starters/unity-wall-following.yaml", tmp_path / "starter.yaml")
    path = tmp_path / "pinned.yaml"
    path.write_text(LAB.format(controller=controller, driver=driver))
    return load_lab(path).exercises[0]


def check(obj, ex, b):
    return check_objective(obj, ex, b, None, attempt_of(b, "lab", ex))


def test_a_run_on_an_easier_copy_does_not_meet_the_exit_objective(tmp_path):
    ex = lab_in(tmp_path)
    obj = ex.objectives[0]
    copy = tmp_path / "copy.txt"
    copy.write_text(EASIER)
    b = LabStation.open(load_maze(copy), "unity", noise="off")
    apply_setup(b, ex.setup, lab="lab", exercise=ex.id)
    b.load_maze(load_maze(copy))  # the student loads their copy (m)
    b.select_algorithm("right-wall")
    quick = run_to_exit(b)
    assert quick.maze == ex.setup.maze.name and quick.maze_digest != ex.setup.maze.digest
    result = check(obj, ex, b)
    assert not result.passed
    assert result.reason == (
        "run 1 got out of a changed copy of 'Ranking - right wall wins', not the lab's maze: "
        "set the exercise up again (a) and drive the maze as it is given"
    )
    apply_setup(b, ex.setup, lab="lab", exercise=ex.id)
    run_to_exit(b)
    result = check(obj, ex, b)
    assert result.passed and result.reason.startswith("run 2 (algorithm right-wall) got out")
    assert result.evidence["maze_digest"] == ex.setup.maze.digest


def test_the_lab_maze_changed_on_disk_after_loading_is_another_maze(tmp_path):
    ex = lab_in(tmp_path)
    pinned = ex.setup.maze.digest
    (tmp_path / "lab-maze.txt").write_text(EASIER)  # someone edits the lab's own file
    b = LabStation.open(load_maze(tmp_path / "lab-maze.txt"), "unity", noise="off")
    apply_setup(b, ex.setup, lab="lab", exercise=ex.id)
    b.load_maze(load_maze(tmp_path / "lab-maze.txt"))  # the file as it is now (m)
    b.select_algorithm("right-wall")
    run_to_exit(b)
    assert not check(ex.objectives[0], ex, b).passed
    apply_setup(b, ex.setup, lab="lab", exercise=ex.id)  # the maze as the lab was loaded with
    assert b.maze.digest() == pinned and b.maze.same_layout(
        load_maze(Path("mazes/rank-wall-wins.txt"))
    )
    run_to_exit(b)
    assert check(ex.objectives[0], ex, b).passed


def test_the_set_up_uses_the_starter_as_it_was_when_the_lab_was_loaded(tmp_path):
    ex = lab_in(tmp_path, controller="starter starter.yaml", driver="fsm")
    (tmp_path / "starter.yaml").write_text("not: [an, fsm")
    b = LabStation.open(load_maze(Path("mazes/erobotic.txt")), "unity", noise="off")
    apply_setup(b, ex.setup, lab="lab", exercise=ex.id)
    assert b.algorithm.name == "starter-unity-wall-following"
    assert Path(b.algorithm.source) == tmp_path / "starter.yaml"


def test_a_lab_whose_maze_or_starter_cannot_be_read_is_refused_at_loading(tmp_path):
    lab_in(tmp_path, controller="starter starter.yaml", driver="fsm")
    (tmp_path / "lab-maze.txt").write_text("#####\n#.Z.#\n#####\n")
    with pytest.raises(LabFileError) as bad_maze:
        load_lab(tmp_path / "pinned.yaml")
    assert str(bad_maze.value).endswith(
        "pinned.yaml:15:15: exercise 'out': objective 'exit': maze 'lab-maze.txt' cannot be read: "
        "line 2: unknown character 'Z' (hint: see every problem with 'workbench maze check FILE')"
    )
    (tmp_path / "lab-maze.txt").write_text(ORIGINAL)
    (tmp_path / "starter.yaml").write_text("not: [an, fsm")
    with pytest.raises(LabFileError) as bad_starter:
        load_lab(tmp_path / "pinned.yaml")
    assert (
        "pinned.yaml:11:19: exercise 'out': controller: starter 'starter.yaml' cannot be read: "
        "YAML syntax" in str(bad_starter.value)
    )
