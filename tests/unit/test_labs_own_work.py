"""An objective passes only on its own exercise's work, done after its set-up: for every kind,
no work passes nothing, and the work of another exercise passes nothing."""

from __future__ import annotations

import re
from pathlib import Path

from tests.stations import run_to_exit
from workbench.control.station import LabStation
from workbench.labs.checks import REDO, ExerciseProgress, apply_setup, evaluate, keep_passed
from workbench.labs.model import Controller, Exercise, LabMaze, Objective, Question, Setup
from workbench.labs.model import hash_answer as hashed
from workbench.labs.progress import LabProgress, evidence_words, signoff_driver
from workbench.sim.sensors import SensorSpec
from workbench.viple.link import Link

MAZES = Path("mazes").resolve()
EROBOTIC = LabMaze.read(MAZES / "erobotic.txt")
RANK = LabMaze.read(MAZES / "rank-wall-wins.txt")
MOVE = '{"servos":[{"isTurn":false,"servoId":-1,"servoSpeed":1}]}'
SENSORS = (SensorSpec("distance", 1, "right"), SensorSpec("distance", 2, "front"))
TOUCH = (SensorSpec("touch", 2, "front"),)


def exercise(ex_id: str, *objectives: Objective, maze=EROBOTIC, profile="unity", questions=()):
    setup = Setup(profile, maze, SENSORS, Controller("keys"))
    return Exercise(ex_id, ex_id, "do it", setup, objectives, tuple(questions))


def question(answer: str) -> Question:
    spec = hashed(answer)
    return Question("q", "?", spec["salt"], frozenset(spec["sha256"]), choices=(answer, "no"))


#: one objective of every kind, as two exercises would both have it
KINDS = {
    "keys": Objective("keys", "drove", keys=("w", "a")),
    "keys-viple": Objective("keys", "drove by VIPLE", keys=("w",), role="tcp"),
    "sensors": Objective("sensors", "sensors", sensors=TOUCH),
    "viple": Objective("viple", "connected", role="tcp"),
    "exit": Objective("exit", "out", maze=RANK, drivers=("any",)),
    "maze-edited": Objective("maze-edited", "edited"),
    "compare": Objective("compare", "compared", algorithms=("right-wall",), mazes=(RANK,)),
    "questions": Objective("questions", "answered"),
}


def station() -> LabStation:
    return LabStation.open(EROBOTIC.maze, "unity", noise="off")


def do_the_work(b: LabStation, kind: str) -> None:
    """What passes an objective of ``kind`` in the exercise set up on ``b``."""
    if kind == "keys":
        b.key("w")
        b.key("a")
    elif kind in ("keys-viple", "viple"):
        link = Link(b, "tcp")
        link.connect("127.0.0.1:50500")
        link.apply(MOVE)
        b.step(30)
        link.disconnect()
        b.step(1)
    elif kind == "sensors":
        b.apply_sensors(TOUCH)
        b.key("w")  # a run with them is the work, not the sensors alone
        b.step(30)
    elif kind in ("exit", "compare"):
        b.load_maze(RANK.maze)
        b.select_algorithm("right-wall")
        b.apply_algorithm_preset()
        run_to_exit(b)
    elif kind == "maze-edited":
        maze = b.maze
        inner = next((x, y) for y in range(1, maze.height - 1) for x in range(1, maze.width - 1)
                     if maze.is_wall(x, y))  # fmt: skip
        b.put_edited_maze(maze.with_block(*inner, wall=False), maze, hand_blocks=1)


def test_every_kind_passes_on_its_own_work_after_its_set_up():
    for kind, obj in KINDS.items():
        ex = exercise("mine", obj, questions=[question("yes")])
        b = station()
        apply_setup(b, ex.setup, lab="lab", exercise="mine")
        do_the_work(b, kind)
        (state,) = evaluate("lab", ex, b, {"q": "yes"}).objectives
        assert state.passed, (kind, state.reason)
        if kind != "questions":
            assert state.evidence["attempt"] == b.attempt.id, kind


def test_no_kind_passes_with_no_work():
    for kind, obj in KINDS.items():
        ex = exercise("mine", obj, questions=[question("yes")])
        b = station()
        b.apply_sensors(TOUCH)  # the robot happens to be as the sensors objective wants
        (state,) = evaluate("lab", ex, b).objectives
        assert not state.passed, kind
        reason = "not answered yet: q" if kind == "questions" else "not set up yet"
        assert state.reason.startswith(reason), (kind, state.reason)


def test_no_kind_passes_with_the_work_of_another_exercise():
    for kind, obj in KINDS.items():
        mine = exercise("mine", obj, questions=[question("yes")])
        other = exercise("other", obj, questions=[question("yes")])
        for mine_set_up_first in (False, True):
            b = station()
            progress = LabProgress("ana")
            if mine_set_up_first:
                progress.set_up(b, _lab(mine, other), mine)
            progress.set_up(b, _lab(mine, other), other)
            do_the_work(b, kind)
            progress.answer(("lab", "other"), "q", "yes")
            assert progress.check("lab", other, b).passed, kind  # the work is the other's
            (state,) = progress.check("lab", mine, b).objectives
            assert not state.passed, (kind, mine_set_up_first, state.reason)


def test_driving_keys_counts_only_on_the_exercises_profile_and_during_it():
    obj = KINDS["keys"]
    ex = exercise("mine", obj, profile="web")
    b = station()
    b.key("w")
    b.key("a")  # before the set-up
    apply_setup(b, ex.setup, lab="lab", exercise="mine")
    b.profile = "unity"  # the profile changed under the exercise
    b.key("w")
    b.key("a")
    assert evaluate("lab", ex, b).objectives[0].reason == "not used yet: w, a"
    b.profile = "web"
    b.key("w")
    b.key("a")
    assert evaluate("lab", ex, b).objectives[0].passed


def test_loading_a_maze_is_not_editing_it():
    ex = exercise("mine", KINDS["maze-edited"])
    b = station()
    apply_setup(b, ex.setup, lab="lab", exercise="mine")
    b.load_maze(RANK.maze)  # another bundled maze, not the set-up one
    (state,) = evaluate("lab", ex, b).objectives
    assert (state.passed, state.reason) == (
        False,
        "the maze has not been edited yet: open the editor (e), add or remove a block",
    )
    b.put_edited_maze(EROBOTIC.maze, RANK.maze, hand_blocks=4)  # edited back into the set-up maze
    assert evaluate("lab", ex, b).objectives[0].reason == (
        "the edits left 'eRobotic lab maze' as set up: add or remove a block"
    )


def _lab(*exercises: Exercise):
    from workbench.labs.model import Lab

    return Lab("lab", "Lab", "", tuple(exercises))


def test_a_pass_keeps_the_run_its_driver_and_the_person_at_the_station(tmp_path):
    ex = exercise("mine", KINDS["exit"])
    b = LabStation.open(EROBOTIC.maze, "unity", noise="off", record_dir=str(tmp_path))
    progress = LabProgress("ana", "ben", drivers={("lab", "mine"): "ben"})
    progress.set_up(b, _lab(ex), ex)
    assert b.person == "ben"  # the exercise's recorded driver is at the station
    b.person = "ana"  # ana takes the keyboard
    do_the_work(b, "exit")
    checked = progress.check("lab", ex, b)
    (state,) = checked.objectives
    assert state.evidence["person"] == "ana" and state.evidence["driver"] == "algorithm right-wall"
    assert state.evidence["record"].endswith("run-001.jsonl")
    assert progress.signoff_driver(checked) == "ana"
    words = evidence_words(state)
    # its measures with the units of its profile, then its record
    figures = r"\d+\.\d s, \d+\.\d unit \(\d+\.\d blocks\), \d+ deg turned, \d+ collisions?"
    assert re.match(
        rf"run 1 by ana \(algorithm right-wall\): {figures}; record run-001\.jsonl sha256 ", words
    ), words
    assert signoff_driver(checked, {"carl"}) == ""  # names nobody of that pair


def test_a_pass_saved_without_evidence_needs_redoing_until_the_work_is_done_again():
    obj = KINDS["keys"]
    ex = exercise("mine", obj)
    old = {
        "lab": "lab", "exercise": "mine", "answers": {},
        "objectives": [{"kind": "keys", "text": "drove", "passed": True, "reason": "used w, a",
                        "evidence": {"keys_used": ["a", "w"]}}],
    }  # fmt: skip
    saved = ExerciseProgress.from_dict(old)
    assert not saved.passed and saved.objectives[0].redo
    b = station()
    shown = keep_passed(saved, evaluate("lab", ex, b))
    assert (shown.objectives[0].passed, shown.objectives[0].reason) == (False, REDO)
    assert keep_passed(shown, evaluate("lab", ex, b)).objectives[0].redo  # still, not dropped
    apply_setup(b, ex.setup, lab="lab", exercise="mine")
    do_the_work(b, "keys")
    again = keep_passed(shown, evaluate("lab", ex, b))
    assert again.passed and not again.objectives[0].redo


def test_a_pass_saved_under_the_old_rules_needs_redoing():
    """Passes saved before a sensors objective needed a run, an exit the run's sensors and an
    edit blocks changed by hand: they were judged by other rules, and are done again."""
    old = {
        "lab": "lab", "exercise": "mine", "answers": {},
        "objectives": [
            {"kind": "sensors", "text": "sensors", "passed": True, "reason": "sensors are ...",
             "evidence": {"attempt": "a1", "sensors": ["touch:2:front"], "person": "ana"}},
            {"kind": "exit", "text": "out", "passed": True, "reason": "run 1 ...",
             "evidence": {"attempt": "a1", "run": 1, "driver": "keys"}},
            {"kind": "maze-edited", "text": "edited", "passed": True, "reason": "edit 1 ...",
             "evidence": {"attempt": "a1", "edit": 1}},
        ],
    }  # fmt: skip
    saved = ExerciseProgress.from_dict(old)
    assert [(o.passed, o.reason) for o in saved.objectives] == [(False, REDO)] * 3
