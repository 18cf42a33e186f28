"""Lab files: the bundled labs load, and every schema error names the file, line and key."""

import re
import shutil
from pathlib import Path

import pytest

from workbench.labs.model import (
    LABS_DIR,
    LabFileError,
    Question,
    hash_answer,
    load_lab,
    load_labs,
)

GOOD = """\
lab: {name}
title: A small lab
exercises:
  - id: drive
    title: Drive
    instructions: |
      Drive with the keys.
    setup:
      profile: unity
      maze: mazes/m.txt
      sensors: [distance:1:right, distance:2:front]
      controller: keys
    objectives:
      - kind: keys
        text: drove
      - kind: questions
        text: answered
    questions:
      - id: port
        text: Which port?
        answer: {{salt: s, step: "1", sha256: [{port_hash}]}}
    signoff: required
"""


@pytest.fixture
def folder(tmp_path):
    (tmp_path / "mazes").mkdir()
    shutil.copy(Path("mazes/erobotic.txt"), tmp_path / "mazes" / "m.txt")
    return tmp_path


def write(folder, text, name="small"):
    path = folder / f"{name}.yaml"
    path.write_text(text)
    return path


def good_text(name="small"):
    digest = hash_answer(1350, salt="s", tolerance=0, step="1")["sha256"][0]
    return GOOD.format(name=name, port_hash=digest)


def test_every_bundled_lab_loads_with_the_exercises_the_course_has():
    labs = {lab.id: lab for lab in load_labs(LABS_DIR)}
    assert set(labs) == {"maze-algorithms", "unity-simulator", "web-simulator"}
    assert len(labs["unity-simulator"].exercises) == 5
    assert len(labs["web-simulator"].exercises) == 6
    for lab in labs.values():
        for ex in lab.exercises:
            assert ex.signoff and ex.instructions.strip() and ex.objectives
            assert ex.setup.maze.path.is_file() and ex.setup.maze.maze.validate() == []


def test_bundled_labs_keep_no_answer_in_clear():
    for path in LABS_DIR.glob("*.yaml"):
        lab = load_lab(path)
        text = path.read_text()
        for ex in lab.exercises:
            for q in ex.questions:
                assert q.hashes
                if q.choices:
                    right = [c for c in q.choices if q.check(c)[0]]
                    assert len(right) == 1, (lab.id, ex.id, q.id)
        assert "clear:" not in text


def test_a_good_small_lab_loads(folder):
    lab = load_lab(write(folder, good_text()))
    ex = lab.exercise("drive")
    assert ex.setup.controller.kind == "keys"
    assert [str(s) for s in ex.setup.sensors] == ["distance:1:right", "distance:2:front"]
    assert ex.objectives[0].keys == ("w", "a", "s", "d", "space")
    assert ex.questions[0].check("1350") == (True, "correct")
    assert ex.questions[0].check("1351") == (False, "not the expected answer")


@pytest.mark.parametrize(
    ("old", "new", "message"),
    [
        ("kind: keys", "kind: drive-keys",
         "small.yaml:14: exercise 'drive': unknown objective kind 'drive-keys' (use one of keys,"),
        ("profile: unity", "profile: unitty",
         "small.yaml:9: exercise 'drive': setup: unknown profile 'unitty' (use one of"),
        ("maze: mazes/m.txt", "maze: mazes/gone.txt",
         "small.yaml:10: exercise 'drive': setup: no file 'mazes/gone.txt'"),
        ("distance:2:front", "distance:1:front",
         "small.yaml:11: exercise 'drive': setup: port 1 is used twice"),
        ("distance:2:front", "sonar:2:front",
         "small.yaml:11: exercise 'drive': setup: unknown sensor kind 'sonar'"),
        ("controller: keys", "controller: robot",
         "small.yaml:12: exercise 'drive': controller: unknown controller 'robot'"),
        ("controller: keys", "controller: algorithm right-wal",
         "small.yaml:12: exercise 'drive': controller: no built-in algorithm 'right-wal'"),
        ("controller: keys", "controller: viple udp",
         "small.yaml:12: exercise 'drive': controller: unknown VIPLE role 'udp'"),
        ("    title: Drive\n", "    title: Drive\n    colour: red\n",
         "small.yaml:6: exercise: unknown key 'colour' (use one of id, title,"),
        ("        text: drove\n", "",
         "small.yaml:14: exercise 'drive': objective 'keys': missing key 'text'"),
        ("signoff: required", "signoff: optional",
         "small.yaml:22: exercise 'drive': sign-off can only be 'required'"),
        ('step: "1", ', 'step: "x", ',
         "small.yaml:21: exercise 'drive': question 'port': answer: step 'x' is not a positive"),
        ('step: "1", ', "",
         "small.yaml:19: exercise 'drive': question 'port': neither choices nor a numeric step"),
        ("lab: small", "lab: other", "small.yaml:1: lab: id 'other' differs from the file name"),
        ("text: Which port?\n", "text: Which port?\n        shown: ssh-port\n",
         "small.yaml:21: exercise 'drive': question 'port': unknown shown value 'ssh-port' (use "
         "viple-tcp-port"),
    ],
)  # fmt: skip
def test_schema_errors_name_the_file_line_key_and_fix(folder, old, new, message):
    text = good_text()
    assert old in text
    with pytest.raises(LabFileError) as err:
        load_lab(write(folder, text.replace(old, new, 1)))
    line, rest = message.removeprefix("small.yaml:").split(": ", 1)
    rest = rest.replace(" (use ", " (hint: use ")
    assert re.search(rf"small\.yaml:{line}:\d+: {re.escape(rest)}", str(err.value)), err.value


def test_every_problem_of_a_lab_file_is_reported_at_once(folder):
    text = (
        good_text()
        .replace("kind: keys", "kind: drive-keys")
        .replace("profile: unity", "profile: unitty")
        .replace("lab: small", "lab: other")
    )
    with pytest.raises(LabFileError) as err:
        load_lab(write(folder, text))
    found = [str(p) for p in err.value.problems]
    assert len(found) == 3, found
    assert re.search(r"small\.yaml:1:\d+: lab: id 'other' differs", found[0])
    assert re.search(r"small\.yaml:9:\d+: exercise 'drive': setup: unknown profile", found[1])
    assert re.search(r"small\.yaml:14:\d+: exercise 'drive': unknown objective kind", found[2])


def test_unknown_objective_kind_lists_the_kinds_and_the_exact_line(folder):
    path = write(folder, good_text().replace("kind: keys", "kind: drive-keys"))
    with pytest.raises(LabFileError) as err:
        load_lab(path)
    assert str(err.value).endswith(
        ":14:15: exercise 'drive': unknown objective kind 'drive-keys' (hint: use one of keys, "
        "sensors, viple, exit, maze-edited, compare, questions, fsm-behaviour)"
    )


def test_exit_objective_checks_its_driver_and_limits(folder):
    exit_obj = (
        "      - kind: exit\n        text: out\n        maze: mazes/m.txt\n"
        "        driver: DRIVER\n        max_time: LIMIT\n"
    )
    base = good_text().replace("      - kind: questions\n", exit_obj + "      - kind: questions\n")

    def lab_with(driver, limit):
        return write(folder, base.replace("DRIVER", driver).replace("LIMIT", limit))

    lab = load_lab(lab_with("[viple, fsm]", "60"))
    obj = lab.exercises[0].objectives[1]
    assert (obj.drivers, obj.max_time) == (("viple", "fsm"), 60.0)
    with pytest.raises(LabFileError, match=r":19:\d+: .*unknown driver 'robot'"):
        load_lab(lab_with("robot", "60"))
    with pytest.raises(LabFileError, match=r":20:\d+: .*max_time: 'soon' is not a number"):
        load_lab(lab_with("fsm", "soon"))


def test_yaml_syntax_errors_and_empty_files_name_the_line(folder):
    with pytest.raises(LabFileError, match=r"small\.yaml:2:\d+: YAML syntax: mapping values"):
        load_lab(write(folder, "lab: small\ntitle: x: y\n"))
    with pytest.raises(LabFileError, match=r"small\.yaml:1:1: empty file"):
        load_lab(write(folder, ""))


def test_choice_answers_ignore_case_and_spacing_and_refuse_other_text():
    q = Question("q", "t", "salt", frozenset(hash_answer("Right wall", salt="salt")["sha256"]),
                 choices=("Right wall", "Left wall"))  # fmt: skip
    assert q.check("  right   WALL ")[0]
    assert q.check("Left wall") == (False, "not the expected answer")
    assert q.check("up") == (False, "'up' is not one of the choices")


def test_numeric_answers_accept_the_tolerance_band_on_the_rounding_grid():
    stored = hash_answer(1500, salt="x", tolerance=200, step="50")
    assert len(stored["sha256"]) == 9 and "1500" not in str(stored)
    q = Question("q", "t", "x", frozenset(stored["sha256"]), step="50")
    assert all(q.check(v)[0] for v in ("1300", "1500", "1700", "1690", "1510.5"))
    assert not any(q.check(v)[0] for v in ("1250", "1750", "-1500"))
    assert q.check("fast") == (False, "'fast' is not a number")
    assert q.check("nan") == (False, "'nan' is not a number")


def test_decimal_steps_round_without_float_noise():
    q = Question("q", "t", "s", frozenset(hash_answer(-0.3, "s", 0, "0.05")["sha256"]), step="0.05")
    assert q.check("-0.3")[0] and q.check("-0.30")[0] and q.check("-.31")[0]
    assert not q.check("0.3")[0]


def test_hash_answer_refuses_a_missing_step_or_a_huge_band():
    with pytest.raises(ValueError, match="rounding step"):
        hash_answer(1, tolerance=1)
    with pytest.raises(ValueError, match="more than 1000"):
        hash_answer(1, tolerance=100, step="0.01")


def test_the_same_answer_hashes_differently_under_another_salt():
    assert hash_answer("a", salt="1")["sha256"] != hash_answer("a", salt="2")["sha256"]


def test_a_set_up_speed_is_read_and_a_wrong_one_is_named(tmp_path):
    lab = Path("labs/unity-simulator.yaml").read_text()
    shutil.copytree("labs/starters", tmp_path / "labs" / "starters")
    shutil.copytree("mazes", tmp_path / "mazes")
    fast = lab.replace("      controller: keys\n", "      controller: keys\n      speed: max\n", 1)
    path = tmp_path / "labs" / "unity-simulator.yaml"
    path.write_text(fast)
    assert load_lab(path).exercises[0].setup.speed is None
    assert load_lab("labs/unity-simulator.yaml").exercises[0].setup.speed == 1.0
    path.write_text(fast.replace("speed: max", "speed: 3"))
    with pytest.raises(LabFileError) as err:
        load_lab(path)
    assert "setup: unknown speed '3' (hint: use one of 1, 2, 4, 10, max)" in str(err.value)


def test_an_exercise_says_what_its_students_programs_are_graded_on(folder):
    exit_obj = (
        "      - kind: exit\n        text: out\n        maze: mazes/other.txt\n"
        "        driver: viple\n"
    )
    shutil.copy(Path("mazes/web.txt"), folder / "mazes" / "other.txt")
    base = good_text().replace("      - kind: questions\n", exit_obj + "      - kind: questions\n")
    graded = load_lab(write(folder, base)).exercises[0].graded
    # by default: the set-up's maze and each exit objective's, seed 0, time from the maze
    assert [m.path.name for m in graded.mazes] == ["m.txt", "other.txt"]
    assert (graded.seeds, graded.max_time) == (1, None)

    def with_grading(lines):
        return write(
            folder, base.replace("    signoff: required\n", lines + "    signoff: required\n")
        )

    own = "    grading:\n      mazes: [mazes/other.txt]\n      seeds: 3\n      max_time: 300\n"
    graded = load_lab(with_grading(own)).exercises[0].graded
    assert ([m.path.name for m in graded.mazes], graded.seeds, graded.max_time) == (
        ["other.txt"],
        3,
        300.0,
    )
    with pytest.raises(LabFileError, match=r":28:\d+: .*grading: seeds must be a whole number"):
        load_lab(with_grading(own.replace("seeds: 3", "seeds: 2.5")))
    with pytest.raises(LabFileError, match=r":29:\d+: .*grading: max_time must be above 0"):
        load_lab(with_grading(own.replace("max_time: 300", "max_time: 0")))
    with pytest.raises(LabFileError, match=r":27:\d+: .*grading: no file 'mazes/gone.txt'"):
        load_lab(with_grading(own.replace("mazes/other.txt", "mazes/gone.txt")))


def test_a_question_takes_a_shown_value_only_once_the_workbench_shows_one(folder):
    text = good_text().replace(
        "text: Which port?\n", "text: Which port?\n        shown: viple-tcp-port\n"
    )
    exercise = load_lab(write(folder, text)).exercises[0]
    (q,) = exercise.questions
    assert q.shown == "viple-tcp-port" and q.check("1350")[0] and not q.check("20345")[0]
    (bound,) = exercise.with_shown({"viple-tcp-port": "20345"}).questions
    assert bound.check("20345") == (
        True, "correct: the TCP port your workbench shows VIPLE's robot listening on")  # fmt: skip
    assert bound.check("1350")[0] and not bound.check("20346")[0]
    assert exercise.with_shown({}) is exercise
