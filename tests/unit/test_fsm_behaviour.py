"""Two machines compared by what they make the robot do: a renamed, reordered copy behaves
the same; one wrong transition is found at the first command that differs."""

import itertools
import re
from pathlib import Path

from workbench.control.fsm_behaviour import Trial, compare
from workbench.fsm.yaml_file import load_fsm, loads_fsm

ALGORITHMS = Path(__file__).resolve().parents[2] / "workbench" / "fsm" / "algorithms"
REFERENCE = ALGORITHMS / "right-wall.yaml"
TRIALS = [Trial("mazes/erobotic.txt", "erobotic", 0)]
SENSORS = ["distance:1:front", "distance:2:left", "distance:3:right"]


def _renamed_and_reordered() -> str:
    """right-wall with every state renamed and the states written in another order."""
    text = REFERENCE.read_text()
    head, states = text.split("states:\n", 1)
    blocks = re.split(r"\n(?=  [A-Za-z]+:\n)", states.strip("\n"))
    text = head + "states:\n" + "\n".join(reversed(blocks)) + "\n"
    for old, new in (("TurningLeft", "Left"), ("TurningRight", "Right"),
                     ("BesideOpening", "Waiting"), ("TurnedRight", "Settle"),
                     ("Forward", "Ahead")):  # fmt: skip
        text = text.replace(old, new)
    return text


def test_a_renamed_reordered_machine_behaves_as_the_reference():
    mine = loads_fsm(_renamed_and_reordered(), "mine.yaml")
    assert next(s.name for s in mine.states) != "Ahead"
    verdict = compare(load_fsm(REFERENCE), mine, TRIALS, "erobotic", SENSORS)
    assert verdict.same, verdict
    assert verdict.commands > 10


def test_one_wrong_transition_is_found_where_it_first_acts():
    back = "      - when: turn_done and timer_done\n        to: "
    text = REFERENCE.read_text().replace(back + "Forward", back + "TurningRight")
    verdict = compare(load_fsm(REFERENCE), loads_fsm(text, "w.yaml"), TRIALS, "erobotic", SENSORS)
    assert not verdict.same and verdict.difference is not None
    d = verdict.difference
    assert (d.reference, d.student) == ("move 1", "turn 90")
    assert d.time > 0 and dict(d.readings)["front"] > 0
    words = d.words("px")
    assert f"at {d.time:.2f} s" in words and "the reference did move 1; yours did turn 90" in words


def test_a_machine_that_fails_while_running_says_so():
    guard = "- when: right > open_right"
    text = REFERENCE.read_text().replace(guard, "- when: right / (front - front) > open_right", 1)
    verdict = compare(load_fsm(REFERENCE), loads_fsm(text, "z.yaml"), TRIALS, "erobotic", SENSORS)
    assert not verdict.same and verdict.difference is not None
    assert "stopped" in verdict.difference.error


def test_the_wall_clock_deadline_stops_a_comparison():
    """A clock read at every tick of both runs: here each reading is 100 s after the last."""
    clock = itertools.count(0.0, 100.0).__next__
    verdict = compare(load_fsm(REFERENCE), load_fsm(REFERENCE), TRIALS, "erobotic", SENSORS,
                      deadline=20.0, clock=clock)  # fmt: skip
    assert not verdict.same and "longer than 20 s" in verdict.problem
