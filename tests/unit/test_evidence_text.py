"""The words of saved evidence (units per profile, programs, sensors, tries) and the copy hints
the console shows, from evidence dicts as the checks save them, old and new."""

from __future__ import annotations

import pytest
from hypothesis import example, given
from hypothesis import strategies as st

from tests.app.console_support import progress, wall_main, wall_run
from workbench.labs.checks import ExerciseProgress, ObjectiveState
from workbench.labs.copy_hints import ProgramUse, bundled_digests, copy_hints, program_uses
from workbench.labs.evidence_text import (
    evidence_lines,
    length_text,
    lines_of_progress,
    measures_of,
    measures_text,
    mixed_programs_text,
    programs_of,
)
from workbench.sim.record import file_sha256


@pytest.mark.parametrize(
    ("profile", "distance", "blocks", "said"),
    [
        ("unity", 149.3333, 74.67, "74.67 blocks (149.33 units)"),
        ("web", 4245.42, 60.65, "60.65 blocks (4245 px)"),
        ("erobotic", 1142.6, 9.52, "9.52 blocks (1143 px)"),
    ],
)
def test_lengths_are_in_blocks_and_the_profiles_own_unit(profile, distance, blocks, said):
    run = {"run": 1, "profile": profile, "ended": "exit",
           "metrics": {"reached_exit": True, "exit_time": 12.34, "distance": distance,
                       "distance_cells": blocks, "turn_degrees": 90.4, "turns": 1,
                       "collisions": 0}}  # fmt: skip
    m = measures_of(run)
    assert m is not None
    assert (
        measures_text(m, unicode=True) == f"out in 12.3 s, {said}, turned 90°, 1 turn, 0 collisions"
    )
    assert "turned 90 deg" in measures_text(m, unicode=False)


def test_old_evidence_without_blocks_takes_the_profiles_block_and_a_cut_run_its_time():
    run = {"run": 2, "profile": "unity", "ended": "time limit",
           "metrics": {"reached_exit": False, "exit_time": None, "sim_time": 300.0,
                       "distance": 12.25}}  # fmt: skip
    m = measures_of(run)
    assert m is not None and m.blocks == pytest.approx(6.125)
    assert measures_text(m) == "ran 300.0 s, 6.12 blocks (12.25 units)"
    assert length_text(666.4, "px") == "666 px" and length_text(0.5, "unit") == "0.50 units"


def test_a_run_says_its_driver_program_and_sensors_and_old_ones_what_they_have():
    new = ObjectiveState("exit", "out", True, "ok", wall_run("ana", "wall.viple", "ab" * 32, "a1"))
    lines = evidence_lines(new, "web")
    assert lines[0] == (
        "run 4 by VIPLE program wall.viple (ana at the station) on Web Simulator lab maze "
        "(web), ended by exit"
    )
    assert (
        lines[1]
        == "program wall.viple (sha256 abababababab); sensors distance:1:right, touch:2:front"
    )
    assert lines[2].startswith("out in 61.2 s, 60.65 blocks (4245 px)")
    kept = progress().objectives[0]
    before = {k: v for k, v in kept.evidence.items() if k not in ("sensors", "hand_blocks")}
    old = ObjectiveState(kept.kind, kept.text, True, "ok", before)  # saved before sensors were
    assert evidence_lines(old, "unity") == [
        "run 3 by keys (ben) on Unity maze (unity), ended by exit",
        "out in 41.5 s, 6.12 blocks (12.25 units), 0 collisions",
    ]


def test_questions_say_their_tries_and_which_wait_for_the_instructor():
    state = ObjectiveState("questions", "q", False, "1 waits",
                           {"correct": 1, "of": 2, "tries": {"base": 1, "margin": 3},
                            "waiting": ["margin"]})  # fmt: skip
    assert evidence_lines(state) == [
        "1 of 2 right; tries: base 1, margin 3",
        "waiting for you (no tries left): margin",
    ]
    old = ObjectiveState("questions", "q", True, "ok", {"correct": 5, "of": 5})
    assert evidence_lines(old) == ["5 of 5 right"]


def test_the_other_kinds_say_their_evidence_in_words():
    keys = ObjectiveState("keys", "k", True, "ok", {"attempt": "a", "profile": "unity",
                          "keys_used": ["a", "w"], "people": ["ben"]})  # fmt: skip
    assert evidence_lines(keys) == ["keys used by ben: a, w"]
    viple = ObjectiveState("viple", "v", True, "ok", {"role": "tcp", "peer": "127.0.0.1:5",
                           "distance": 140.0, "turn_degrees": 90.0})  # fmt: skip
    assert evidence_lines(viple, "web") == [
        "VIPLE tcp program at 127.0.0.1:5, drove 2.00 blocks (140 px), turned 90 deg"
    ]
    sensors = ObjectiveState("sensors", "s", True, "ok", {"sensors": ["distance:1:right"]})
    assert evidence_lines(sensors) == ["sensors set: distance:1:right"]
    row = {"algorithm": "right-wall", **wall_run("ana", "x", "", "a", 7)}
    del row["program_sha256"]
    compare = ObjectiveState("compare", "c", True, "ok", {"runs": [row]})
    (line,) = evidence_lines(compare, "web")
    assert line.startswith("right-wall run 7 on Web Simulator lab maze with distance:1:right")
    assert "60.65 blocks (4245 px)" in line


def test_objectives_on_one_run_say_it_once():
    lines = lines_of_progress(progress(), "unity", unicode=True, marks=("✓", "✗"))
    assert lines[0].startswith("✓ drove with w, a, s, d and space")
    assert lines.count("    on run 3, as above") == 2


def test_evidence_on_two_programs_is_said_and_bundled_files_are_no_program_of_the_student():
    mixed = wall_main("ana", sensors_program=("other.viple", "cd" * 32))
    assert programs_of(mixed) == {"ab" * 32: "wall.viple", "cd" * 32: "other.viple"}
    assert mixed_programs_text(programs_of(mixed)) == (
        "the evidence mixes 2 programs: wall.viple (abababababab), other.viple (cdcdcdcdcdcd)"
    )
    assert mixed_programs_text(programs_of(wall_main("ana"))) == ""
    assert programs_of(mixed, frozenset({"cd" * 32})) == {"ab" * 32: "wall.viple"}
    files = ("programs/right-wall.viple", "labs/starters/web-two-distance.yaml",
             "workbench/fsm/algorithms/right-wall.yaml")  # fmt: skip
    shipped = {file_sha256(p) for p in files}
    assert shipped <= bundled_digests()


def test_copy_hints_leave_out_pairs_and_one_station_and_name_the_rest():
    def use(student: str, digest: str = "ab", attempt: str = "") -> ProgramUse:
        return ProgramUse(student, "web-simulator", "wall-main", digest, "wall.viple",
                          attempt or student)  # fmt: skip

    assert copy_hints([use("ana"), use("ben", attempt="ana")]) == ()  # one station
    assert copy_hints([use("ana"), use("ben")], pairs=[("ben", "ana")]) == ()  # partners
    assert copy_hints([use("ana"), use("ana", attempt="x")]) == ()  # the same student
    assert copy_hints([use("ana"), use("ben", "cd")]) == ()
    (hint,) = copy_hints([use("cat"), use("ana"), use("dan", "cd")])
    assert hint.students == ("ana", "cat") and hint.name == "wall.viple"


def test_only_passed_objectives_count_as_a_program_a_student_used():
    done = wall_main("ana")
    assert [u.digest for u in program_uses("ana", done)] == ["ab" * 32]
    failing = ExerciseProgress(done.lab, done.exercise, [
        ObjectiveState(o.kind, o.text, False, "not yet", o.evidence) for o in done.objectives
    ])  # fmt: skip
    assert program_uses("ana", failing) == []
    assert program_uses("ana", done, frozenset({"ab" * 32})) == []


JSON = st.recursive(
    st.none() | st.booleans() | st.integers() | st.floats(allow_nan=False) | st.text(max_size=8),
    lambda inner: (
        st.lists(inner, max_size=3) | st.dictionaries(st.text(max_size=8), inner, max_size=3)
    ),
    max_leaves=12,
)
KEYS = st.sampled_from(
    [
        "run",
        "metrics",
        "sensors",
        "program_sha256",
        "program_name",
        "tries",
        "waiting",
        "runs",
        "role",
        "distance",
        "profile",
        "correct",
        "edit",
        "trials",
        "reference",
        "compared",
    ]
)


@given(
    kind=st.sampled_from(
        [
            "exit",
            "sensors",
            "questions",
            "keys",
            "viple",
            "maze-edited",
            "compare",
            "fsm-behaviour",
            "other",
        ]
    ),
    evidence=st.dictionaries(KEYS | st.text(max_size=6), JSON, max_size=6)
    | st.lists(JSON, max_size=2),
    profile=st.sampled_from(["unity", "web", "erobotic", "", "nonsense"]),
)
@example(kind="fsm-behaviour", evidence={"\n": False}, profile="unity")
@example(kind="other", evidence={"note": "two\nlines"}, profile="")
def test_any_saved_evidence_is_said_without_an_error(kind, evidence, profile):
    """Evidence read back from a store may be old, odd or edited: it is said, never a crash."""
    state = ObjectiveState(kind, "t", True, "r", evidence)
    lines = evidence_lines(state, profile)
    assert all(isinstance(line, str) and "\n" not in line for line in lines)
    progress_ = ExerciseProgress("lab", "ex", [state, state])
    lines_of_progress(progress_, profile, unicode=False)
    programs_of(progress_)
    program_uses("ana", progress_)
