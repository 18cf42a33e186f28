"""The "draw the state machine" objective (fsm-behaviour): the student's own FSM file, as it
ran in the exercise, is judged by what it does against the reference machine. A renamed,
reordered equivalent passes; one wrong transition fails with the first difference; the
shipped file run as it is, or a file changed since it ran, does not count."""

from __future__ import annotations

import re
from pathlib import Path

import yaml

from workbench.control.station import LabStation
from workbench.files.workspace import FileAccess
from workbench.labs.behaviour import BehaviourJudge
from workbench.labs.checks import apply_setup, evaluate, proven
from workbench.labs.model import load_lab

ROOT = Path(__file__).resolve().parents[2]
REFERENCE = ROOT / "workbench" / "fsm" / "algorithms" / "right-wall.yaml"
LAB = load_lab(ROOT / "labs" / "maze-algorithms.yaml")
EXERCISE = LAB.exercise("draw-right-wall")


def renamed_and_reordered() -> str:
    """The right-wall machine as a student might write it for the eRobotic profile: the
    states renamed and written in another order, and the numbers in its guards and actions
    instead of parameters. It behaves as the built-in, and it is not the built-in's file."""
    machine = yaml.safe_load(REFERENCE.read_text())
    values = {name: p["default"]["erobotic"] for name, p in machine.pop("parameters").items()}
    names = {"TurningLeft": "Left", "TurningRight": "Right", "BesideOpening": "Waiting",
             "TurnedRight": "Settle", "Forward": "Ahead"}  # fmt: skip

    def literal(value):
        if isinstance(value, str):
            for name, number in values.items():
                value = re.sub(rf"\b{name}\b", repr(number), value)
            return names.get(value, value)
        if isinstance(value, list):
            return [literal(v) for v in value]
        if isinstance(value, dict):
            return {names.get(k, k): literal(v) for k, v in value.items() if k != "description"}
        return value

    mine = literal(machine)
    mine["name"] = "mine"
    mine["states"] = dict(reversed(list(mine["states"].items())))
    return yaml.safe_dump(mine, sort_keys=False)


def station_in(tmp_path: Path) -> LabStation:
    files = FileAccess.confined_to(tmp_path / "ann")
    station = LabStation.open(EXERCISE.setup.maze.maze, "erobotic", noise="off", files=files)
    apply_setup(station, EXERCISE.setup, lab=LAB.id, exercise=EXERCISE.id)
    return station


def run_file(station: LabStation, name: str, text: str | None = None) -> None:
    if text is not None:
        assert station.files.workspace is not None
        (station.files.workspace / name).write_text(text)
    station.select_algorithm(name)
    station.start()
    station.step(60)


def judged(station: LabStation):
    judge = BehaviourJudge(station.files, inline=True)
    (state,) = evaluate(LAB.id, EXERCISE, station, judge=judge).objectives
    return state


def test_a_renamed_reordered_machine_of_the_students_passes(tmp_path):
    station = station_in(tmp_path)
    run_file(station, "mine.yaml", renamed_and_reordered())
    state = judged(station)
    assert state.passed, state.reason
    assert "did as right-wall did" in state.reason and "on 2 runs" in state.reason
    assert state.evidence["reference"] == "right-wall" and state.evidence["compared"] > 10
    assert state.evidence["program_name"] == "mine.yaml"
    assert proven(state)


def test_one_wrong_transition_fails_with_the_first_difference(tmp_path):
    station = station_in(tmp_path)
    blocked = "- when: front < 50\n      to: "
    mine = renamed_and_reordered()
    assert blocked + "Left" in mine
    wrong = mine.replace(blocked + "Left", blocked + "Right", 1)
    run_file(station, "mine.yaml", wrong)
    state = judged(station)
    assert not state.passed
    assert re.search(r"differs from right-wall: on 'eRobotic lab maze' at \d+\.\d\d s "
                     r"\(sensors read front [\d.]+ px, right [\d.]+ px\) the reference did "
                     r"turn -90; yours did turn 90", state.reason), state.reason  # fmt: skip


def test_the_shipped_machine_or_a_changed_file_does_not_count(tmp_path):
    station = station_in(tmp_path)
    run_file(station, str(REFERENCE))
    assert "comes with the workbench" in judged(station).reason
    run_file(station, "copy.yaml", REFERENCE.read_text())  # a copy is still the shipped one
    assert "comes with the workbench" in judged(station).reason
    # so is a copy with its states renamed and written in another order
    text = REFERENCE.read_text()
    head, states = text.split("states:\n", 1)
    blocks = re.split(r"\n(?=  [A-Za-z]+:\n)", states.strip("\n"))
    renamed = head + "states:\n" + "\n".join(reversed(blocks)) + "\n"
    for old, new in (("TurningLeft", "Left"), ("Forward", "Ahead"), ("BesideOpening", "Wait")):
        renamed = renamed.replace(old, new)
    run_file(station, "renamed.yaml", renamed)
    assert "comes with the workbench" in judged(station).reason
    run_file(station, "mine.yaml", renamed_and_reordered())
    assert station.files.workspace is not None
    (station.files.workspace / "mine.yaml").write_text(renamed_and_reordered() + "# later\n")
    assert "has changed since it ran" in judged(station).reason


def test_nothing_run_yet_says_what_to_do(tmp_path):
    state = judged(station_in(tmp_path))
    assert not state.passed and "FSM editor (F)" in state.reason


def test_the_judge_works_beside_the_caller_and_keeps_its_verdict(tmp_path):
    station = station_in(tmp_path)
    run_file(station, "mine.yaml", renamed_and_reordered())
    judge = BehaviourJudge(station.files)
    (first,) = evaluate(LAB.id, EXERCISE, station, judge=judge).objectives
    assert first.reason.startswith("comparing run 1")
    judge.wait(60)
    (then,) = evaluate(LAB.id, EXERCISE, station, judge=judge).objectives
    assert then.passed and not judge.busy
    judge.close()


def test_a_closed_judge_compares_nothing_more(tmp_path):
    station = station_in(tmp_path)
    run_file(station, "mine.yaml", renamed_and_reordered())
    judge = BehaviourJudge(station.files)
    judge.close()
    evaluate(LAB.id, EXERCISE, station, judge=judge)
    judge.wait(60)
    (state,) = evaluate(LAB.id, EXERCISE, station, judge=judge).objectives
    assert not state.passed and "the workbench is closing" in state.reason
