"""Each objective kind passes and fails with the one-line reason the app shows."""

import json
from pathlib import Path

import pytest

from tests.stations import run_to_exit
from workbench.control.station import LabStation
from workbench.fsm.yaml_file import load_fsm
from workbench.labs.checks import (
    ExerciseProgress,
    apply_setup,
    attempt_of,
    check_objective,
    evaluate,
    keep_passed,
)
from workbench.labs.model import (
    Controller,
    Exercise,
    LabMaze,
    Objective,
    Question,
    Setup,
    hash_answer,
)
from workbench.sim.sensors import SensorSpec
from workbench.viple.link import Link

MAZES = Path("mazes").resolve()
EROBOTIC = LabMaze.read(MAZES / "erobotic.txt")
RANK = LabMaze.read(MAZES / "rank-wall-wins.txt")
MOVE = '{"servos":[{"isTurn":false,"servoId":-1,"servoSpeed":1}]}'
RIGHT_WALL = ["distance:1:right", "distance:2:front"]


def exercise(*objectives, questions=(), maze=EROBOTIC, profile="unity", controller="keys"):
    kind, _, value = controller.partition(" ")
    starter = load_fsm(value) if kind == "starter" else None
    setup = Setup(profile, maze, tuple(SensorSpec.parse(s) for s in RIGHT_WALL),
                  Controller(kind, value, starter))  # fmt: skip
    return Exercise("ex", "Ex", "do it", setup, tuple(objectives), tuple(questions))


def station_for(ex):
    b = LabStation.open(ex.setup.maze.maze, ex.setup.profile, noise="off")
    apply_setup(b, ex.setup, lab="lab", exercise=ex.id)
    return b


def check(obj, ex, b, answers=None):
    result = check_objective(obj, ex, b, answers, attempt_of(b, "lab", ex))
    return result.passed, result.reason


def evidence_of(obj, ex, b):
    return check_objective(obj, ex, b, None, attempt_of(b, "lab", ex)).evidence


def test_keys_objective_names_the_keys_still_to_use():
    obj = Objective("keys", "drove", keys=("w", "a", "s", "d", "space"))
    ex = exercise(obj)
    b = station_for(ex)
    for key in ("w", "d"):
        b.key(key)
    assert check(obj, ex, b) == (False, "not used yet: a, s, space")
    for key in ("a", "s", "space"):
        b.key(key)
    assert check(obj, ex, b) == (True, "used w, a, s, d, space")


def test_sensors_objective_lists_what_is_missing_and_what_is_extra():
    want = (SensorSpec("distance", 1, "right"), SensorSpec("touch", 2, "front"))
    obj = Objective("sensors", "sensors", sensors=want)
    ex = exercise(obj)
    b = station_for(ex)
    assert check(obj, ex, b) == (
        False,
        "missing touch:2:front; not wanted distance:2:front: fit them (sensor panel, o), "
        "then drive a run",
    )
    b.apply_sensors(want)
    # fitting them is not the work: a run with them is
    assert check(obj, ex, b) == (
        False,
        "the robot carries them: now drive it (keys, x or VIPLE) for a run",
    )
    b.key("w")
    b.step(30)
    assert check(obj, ex, b) == (True, "run 1 (keys) carried distance:1:right, touch:2:front")
    b.reset_robot()
    evidence = evidence_of(obj, ex, b)
    assert evidence["run"] == 1 and evidence["driver"] == "keys"
    assert evidence["sensors"] == ["distance:1:right", "touch:2:front"]
    assert evidence["attempt"] == b.attempt.id and evidence["ended"] == "reset"


def test_a_sensors_objective_is_not_met_by_the_sensors_the_set_up_fits():
    """The set-up puts the objective's own sensors on the robot: that alone passes nothing."""
    obj = Objective("sensors", "sensors", sensors=tuple(SensorSpec.parse(s) for s in RIGHT_WALL))
    ex = exercise(obj)
    b = station_for(ex)
    assert [str(s) for s in b.sensors] == RIGHT_WALL
    assert check(obj, ex, b)[0] is False
    b.key("space")  # a run that goes nowhere is no run with the sensors
    b.step(10)
    assert check(obj, ex, b)[0] is False


def test_a_run_whose_sensors_changed_carries_both_sets():
    want = (SensorSpec("distance", 1, "right"), SensorSpec("touch", 2, "front"))
    obj = Objective("sensors", "sensors", sensors=want)
    ex = exercise(obj)
    b = station_for(ex)
    b.key("w")
    b.step(30)
    b.apply_sensors(want)  # fitted while the run goes on
    b.step(30)
    assert check(obj, ex, b) == (
        False,
        "run 1 carried other sensors (not wanted distance:2:front): they changed during it; "
        "reset the robot (r on the maze) and drive a run with only these",
    )
    b.reset_robot()
    assert [str(s) for s in b.runs[-1].sensors] == [
        "distance:1:right", "distance:2:front", "touch:2:front"]  # fmt: skip
    b.key("w")
    b.step(30)
    assert check(obj, ex, b) == (True, "run 2 (keys) carried distance:1:right, touch:2:front")


def test_viple_objective_needs_the_role_and_real_driving():
    obj = Objective("viple", "connected", role="tcp")
    ex = exercise(obj)
    b = station_for(ex)
    assert check(obj, ex, b) == (
        False,
        "no VIPLE program has connected over TCP (the Unity simulator's role) yet",
    )
    ws = Link(b, "ws")
    ws.connect("ws://localhost:8124/")
    ws.apply(MOVE)
    b.step(30)
    ws.disconnect()
    b.step(1)
    assert check(obj, ex, b) == (
        False,
        "VIPLE connected over ws; this exercise needs TCP (the Unity simulator's role)",
    )
    tcp = Link(b, "tcp")
    tcp.connect("127.0.0.1:50000")
    b.step(5)
    assert check(obj, ex, b) == (False, "VIPLE tcp program connected but has not moved the robot")
    tcp.apply(MOVE)
    b.step(30)
    passed, reason = check(obj, ex, b)
    assert (passed, reason) == (True, "VIPLE tcp program at 127.0.0.1:50000 drove the robot")
    assert evidence_of(obj, ex, b)["distance"] > 0


def test_exit_objective_wants_the_right_kind_of_driver_on_the_right_maze():
    obj = Objective("exit", "out", maze=EROBOTIC, drivers=("fsm",))
    ex = exercise(obj)
    b = station_for(ex)
    assert check(obj, ex, b) == (
        False,
        "no run by fsm has reached the exit of 'eRobotic lab maze' (unity) yet",
    )
    b.select_algorithm("right-wall")
    run_to_exit(b)
    assert check(obj, ex, b)[0] is False  # a built-in is not the student's FSM
    b.select_algorithm("labs/starters/unity-wall-following.yaml")
    b.set_params(["open_right=1.0", "front_blocked=0.9", "right_turn=90", "left_turn=-90"])
    run = run_to_exit(b)
    passed, reason = check(obj, ex, b)
    assert passed and reason.startswith(
        f"run {run.number} (algorithm starter-unity-wall-following)"
    )
    evidence = evidence_of(obj, ex, b)
    assert evidence["run"] == run.number and evidence["metrics"]["reached_exit"] is True
    assert evidence["maze_digest"] == EROBOTIC.maze.digest()


def test_exit_objective_accepts_a_named_algorithm_and_reports_a_broken_limit():
    obj = Objective("exit", "out", maze=RANK, drivers=("algorithm right-wall",), max_time=5)
    ex = exercise(obj, maze=RANK)
    b = station_for(ex)
    b.select_algorithm("right-wall")
    run = run_to_exit(b)
    passed, reason = check(obj, ex, b)
    assert not passed
    assert (
        reason
        == f"run 1 (algorithm right-wall) took {run.metrics.exit_time:.1f} s, over the 5 s limit"
    )
    roomy = Objective("exit", "out", maze=RANK, drivers=("algorithm right-wall",), max_time=60,
                      max_turn_degrees=45)  # fmt: skip
    assert check(roomy, ex, b) == (
        False,
        "run 1 (algorithm right-wall) turned 90°, over the 45° limit",
    )
    fine = Objective("exit", "out", maze=RANK, drivers=("algorithm right-wall",), max_time=60,
                     max_turn_degrees=90, max_collisions=0)  # fmt: skip
    assert check(fine, ex, b)[0]


def test_exit_objective_with_a_record_keeps_its_digest(tmp_path):
    obj = Objective("exit", "out", maze=RANK, drivers=("any",))
    ex = exercise(obj, maze=RANK)
    b = LabStation.open(RANK.maze, "unity", noise="off", record_dir=str(tmp_path))
    apply_setup(b, ex.setup, lab="lab", exercise=ex.id)
    b.select_algorithm("right-wall")
    run_to_exit(b)
    evidence = evidence_of(obj, ex, b)
    assert evidence["record"].endswith("run-001.jsonl") and len(evidence["record_sha256"]) == 64


def test_maze_edited_objective_wants_a_change_and_a_valid_maze():
    obj = Objective("maze-edited", "edited")
    ex = exercise(obj)
    b = station_for(ex)
    assert check(obj, ex, b) == (
        False,
        "the maze has not been edited yet: open the editor (e), add or remove a block",
    )
    maze = b.maze
    b.load_maze(RANK.maze)  # loading another maze is not editing
    assert not check(obj, ex, b)[0]
    b.load_maze(maze)
    # a hole in the outer wall
    b.put_edited_maze(maze.with_block(0, 0, wall=False), maze, hand_blocks=1)
    assert check(obj, ex, b) == (
        False,
        "the edited maze has problems: fix them in the editor (e)",
    )
    inner = next((x, y) for y in range(1, maze.height - 1) for x in range(1, maze.width - 1)
                 if maze.is_wall(x, y))  # fmt: skip
    edited = maze.with_block(*inner, wall=False)
    b.put_edited_maze(edited, maze, hand_blocks=0)  # as Generate would leave it: not by hand
    assert check(obj, ex, b) == (
        False,
        "edit 2 added or removed no block by hand (Generate, New and loading do not count): "
        "in the editor (e) put or take away a block yourself",
    )
    b.put_edited_maze(edited, maze, hand_blocks=1)
    assert check(obj, ex, b) == (True, f"edit 3 changed 1 block by hand, {edited.name!r}")
    evidence = evidence_of(obj, ex, b)
    assert evidence["edit"] == 3 and evidence["maze_digest"] == edited.digest()
    assert evidence["hand_blocks"] == 1


def test_compare_objective_names_the_missing_runs():
    obj = Objective("compare", "compared", algorithms=("right-wall", "two-distance-local-best"),
                    mazes=(RANK,))  # fmt: skip
    ex = exercise(obj, maze=RANK)
    b = station_for(ex)
    assert check(obj, ex, b) == (
        False,
        "no run to the exit yet: right-wall on 'Ranking - right wall wins' (unity) (+1 more)",
    )
    b.select_algorithm("right-wall")
    run_to_exit(b)
    assert check(obj, ex, b) == (
        False,
        "no run to the exit yet: two-distance-local-best on 'Ranking - right wall wins' (unity)",
    )
    b.select_algorithm("two-distance-local-best")
    run_to_exit(b)
    assert check(obj, ex, b) == (True, "2 runs to compare")
    table = evidence_of(obj, ex, b)["runs"]
    assert [r["algorithm"] for r in table] == ["right-wall", "two-distance-local-best"]


def question(qid, answer, **kw):
    stored = hash_answer(answer, salt="s", **kw)
    return Question(qid, "?", "s", frozenset(stored["sha256"]), step=stored.get("step"),
                    choices=("a", "b") if "step" not in stored else ())  # fmt: skip


def test_questions_objective_counts_unanswered_and_wrong_answers():
    obj = Objective("questions", "answered")
    qs = (question("one", "a"), question("two", 90, tolerance=0, step="1"))
    ex = exercise(obj, questions=qs)
    b = station_for(ex)
    assert check(obj, ex, b, {}) == (False, "not answered yet: one, two")
    assert check(obj, ex, b, {"one": "b", "two": "90"}) == (False, "1 of 2 not right yet: one")
    assert check(obj, ex, b, {"one": "A", "two": "90"}) == (True, "all 2 answered correctly")


def test_progress_round_trips_through_json_and_has_a_stable_digest():
    keys = Objective("keys", "drove", keys=("w",))
    ex = exercise(keys)
    b = station_for(ex)
    before = evaluate("lab", ex, b)
    assert not before.passed and before.objectives[0].reason == "not used yet: w"
    b.key("w")
    after = evaluate("lab", ex, b)
    assert after.passed
    text = after.to_json()
    assert json.loads(text)["passed"] is True
    again = ExerciseProgress.from_json(text)
    assert again == after and again.evidence_digest() == after.evidence_digest()
    assert before.evidence_digest() != after.evidence_digest()


def test_apply_setup_puts_profile_maze_sensors_and_controller_on_the_station():
    ex = exercise(
        maze=RANK, profile="web", controller="starter labs/starters/web-two-distance.yaml"
    )
    b = LabStation.open(EROBOTIC.maze, "unity", noise="off")
    apply_setup(b, ex.setup, lab="lab", exercise=ex.id)
    assert (b.profile, b.maze.name) == ("web", "Ranking - right wall wins")
    assert [str(s) for s in b.sensors] == RIGHT_WALL
    assert b.algorithm.name == "starter-web-two-distance"


@pytest.mark.parametrize("starter", sorted(Path("labs/starters").glob("*.yaml")))
def test_every_starter_loads_and_runs_but_does_not_get_out_as_given(starter):
    b = LabStation.open(EROBOTIC.maze, "unity" if "unity" in starter.name else "web", noise="off")
    b.select_algorithm(starter)
    b.apply_algorithm_preset()
    b.start()
    b.step(60 * 120)
    assert b.notice is None and b.driving is not None
    assert not b.session.reached_exit


def test_runs_on_another_profile_do_not_count():
    obj = Objective("exit", "out", maze=RANK, drivers=("algorithm right-wall",))
    ex = exercise(obj, maze=RANK, profile="web")
    b = LabStation.open(RANK.maze, "unity", noise="off")
    b.select_algorithm("right-wall")
    run_to_exit(b)
    apply_setup(b, ex.setup, lab="lab", exercise=ex.id)
    b.profile = "unity"  # the profile changed after the set-up
    b.load_maze(RANK.maze)
    b.select_algorithm("right-wall")
    run_to_exit(b)
    assert check(obj, ex, b) == (
        False,
        "no run by algorithm right-wall has reached the exit of 'Ranking - right wall wins' "
        "(web) yet",
    )
    apply_setup(b, ex.setup, lab="lab", exercise=ex.id)
    b.select_algorithm("right-wall")
    run_to_exit(b)
    assert check(obj, ex, b)[0]


def test_objectives_that_passed_before_stay_passed_with_their_evidence():
    keys = Objective("keys", "drove", keys=("w", "a"))
    sensors = Objective("sensors", "sensors", sensors=(SensorSpec("touch", 2, "front"),))
    asked = Objective("questions", "answers")
    ex = exercise(keys, sensors, asked, questions=[question("q", "a")])
    first = station_for(ex)
    first.key("w")
    first.key("a")
    earlier = evaluate("lab", ex, first, {"q": "a"})
    assert [o.passed for o in earlier.objectives] == [True, False, True]
    saved = ExerciseProgress.from_dict(json.loads(earlier.to_json()))  # as the store keeps it

    again = station_for(ex)  # a new app: no keys used yet, the answer changed to a wrong one
    progress = keep_passed(saved, evaluate("lab", ex, again, {"q": "b"}))
    drove, sensed, answered = progress.objectives
    assert (drove.passed, drove.reason) == (True, "passed earlier: used w, a")
    assert drove.evidence == {"attempt": first.attempt.id, "keys_used": ["a", "w"],
                              "people": [], "profile": "unity"}  # fmt: skip
    assert not sensed.passed  # it never passed
    assert not answered.passed  # answers are judged as they stand now
    assert keep_passed(progress, progress).objectives[0].reason == "passed earlier: used w, a"
    renamed = Exercise(ex.id, ex.title, ex.instructions, ex.setup,
                       (Objective("keys", "drove all", keys=("w", "a")),), ())  # fmt: skip
    assert not keep_passed(saved, evaluate("lab", renamed, again)).objectives[0].passed


def test_saved_progress_in_the_wrong_shape_is_refused_with_a_reason():
    with pytest.raises(ValueError, match="not in the expected shape"):
        ExerciseProgress.from_dict({"lab": "x", "exercise": "y", "objectives": [{"kind": 1}]})
    with pytest.raises(ValueError, match="not in the expected shape"):
        ExerciseProgress.from_dict({"lab": "x"})
    state = {"kind": "exit", "text": "out", "passed": True, "reason": "ok"}
    for bad in ({**state, "evidence": []}, {**state, "evidence": "run 3"}):
        with pytest.raises(ValueError, match="evidence is not a mapping"):
            ExerciseProgress.from_dict({"lab": "x", "exercise": "y", "objectives": [bad]})
    with pytest.raises(ValueError, match="not in the expected shape"):  # tries: 1e999
        ExerciseProgress.from_dict(
            {"lab": "x", "exercise": "y", "objectives": [], "tries": {"q": float("inf")}}
        )
    kept = ExerciseProgress.from_dict(
        {"lab": "x", "exercise": "y", "objectives": [], "tries": {"q": -5}}
    )
    assert kept.tries == {"q": 0}  # a negative count never buys tries past max_tries


def test_the_set_up_starts_the_exercise_afresh():
    obj = Objective("keys", "drove", keys=("w",))
    ex = exercise(obj)
    b = station_for(ex)
    b.key("w")
    assert check(obj, ex, b)[0]
    apply_setup(b, ex.setup, lab="lab", exercise=ex.id)
    assert check(obj, ex, b) == (False, "not used yet: w")


def test_keys_objective_with_a_role_accepts_a_viple_program_making_the_five_motions():
    obj = Objective("keys", "drove", keys=("w", "a", "s", "d", "space"), role="tcp")
    ex = exercise(obj)
    b = station_for(ex)
    assert check(obj, ex, b) == (False, "not used yet: w, a, s, d, space")
    link = Link(b, "tcp")
    link.connect("127.0.0.1:50500")
    turn = '{"servos":[{"isTurn":true,"servoId":-1,"servoSpeed":%d}]}'
    for message in (MOVE, turn % 90, MOVE.replace(":1}", ":-1}")):
        assert link.apply(message)
        b.step(20)
    assert check(obj, ex, b) == (False, "VIPLE has not asked for left, stop yet")
    for message in (turn % -90, MOVE.replace(":1}", ":0}")):
        assert link.apply(message)
        b.step(20)
    assert check(obj, ex, b) == (
        True,
        "VIPLE tcp program asked for forward, left, backward, right, stop",
    )
    evidence = evidence_of(obj, ex, b)
    assert evidence == {"attempt": b.attempt.id, "role": "tcp", "peer": "127.0.0.1:50500",
                        "person": "",
                        "motions": ["backward", "forward", "left", "right", "stop"]}  # fmt: skip
    other = Objective("keys", "drove", keys=("w",), role="ws")
    assert check(other, exercise(other), b) == (False, "not used yet: w")  # tcp is not ws


def test_a_viple_exercise_passes_with_the_students_program_run_here(tmp_path):
    import hashlib

    from tests.students_work import own_right_wall
    from workbench.program.choice import choose_program

    web = LabMaze.read(MAZES / "web.txt")
    for_viple = Objective("exit", "out", maze=web, drivers=("viple",))
    for_fsm = Objective("exit", "out", maze=web, drivers=("fsm",))
    sensors = tuple(SensorSpec.parse(s) for s in ("distance:1:right", "touch:2:front"))
    ex = Exercise("ex", "Ex", "do it", Setup("web", web, sensors, Controller("keys", "")),
                  (for_viple, for_fsm), ())  # fmt: skip
    b = station_for(ex)
    mine = own_right_wall(tmp_path)
    choose_program(b, str(mine))
    b.start()
    for _ in range(200):
        b.step(60)
        if b.runs and b.runs[-1].ended == "exit":
            break
    run = b.runs[-1]
    assert run.ended == "exit" and str(run.driver) == "VIPLE program my-right-wall.viple"
    passed, reason = check(for_viple, ex, b)
    assert passed and reason.startswith(f"run {run.number} (VIPLE program my-right-wall.viple)")
    evidence = evidence_of(for_viple, ex, b)
    digest = hashlib.sha256(mine.read_bytes()).hexdigest()
    assert evidence["program_sha256"] == digest
    assert evidence["program_name"] == "my-right-wall.viple"
    assert evidence["sensors"] == ["distance:1:right", "touch:2:front"]
    assert check(for_fsm, ex, b)[0] is False  # a VIPLE program is not an FSM file


def test_set_up_starts_afresh_speed_algorithm_and_parameters():
    b = LabStation.open(EROBOTIC.maze, "erobotic", noise="off")
    b.select_algorithm("one-distance-first")
    b.set_params(["right_blocked=50"])
    b.pacer.set_speed(None)  # "max"
    keys_exercise = exercise(profile="web")
    changes = apply_setup(b, keys_exercise.setup, lab="lab", exercise="ex")
    assert b.pacer.speed == 1.0 and b.algorithm is None and b.overrides == {}
    assert changes.speed == (None, 1.0)
    assert changes.algorithm == ("one-distance-first", None)

    setup = exercise(profile="web", controller="algorithm one-distance-first").setup
    apply_setup(b, setup, lab="lab", exercise="ex")
    b.set_params(["right_blocked=50"])
    changes = apply_setup(b, setup, lab="lab", exercise="ex")
    web = LabStation.open(EROBOTIC.maze, "web", noise="off")
    web.select_algorithm("one-distance-first")
    assert b.params() == web.params()  # the web profile's own values, not the edited ones
    assert changes.params_reset and changes.algorithm is None and changes.speed is None


def test_set_up_with_nothing_to_change_reports_nothing():
    ex = exercise(controller="algorithm right-wall")
    b = station_for(ex)
    changes = apply_setup(b, ex.setup, lab="lab", exercise=ex.id)
    assert changes == type(changes)()
