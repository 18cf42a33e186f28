"""The FSM editor's forms write YAML lines that the loader reads back, and leave the rest of
the student's text as it was."""

import pytest

from workbench.files.workspace import FileAccess
from workbench.fsm.editing import FsmDraft, FsmEditError, check
from workbench.fsm.forms import FormError, add_state, add_transition, new_text
from workbench.fsm.yaml_file import loads_fsm
from workbench.sim.sensors import SensorSpec

SENSORS = [SensorSpec("distance", 1, "front"), SensorSpec("distance", 3, "right")]


def test_a_machine_built_through_the_forms_loads():
    text = new_text("mine", SENSORS, "erobotic")
    text = add_state(text, "Ahead", "move: 1").text
    text = add_state(text, "Left", "turn: -90; timer: 0.5").text
    text = add_transition(text, "Ahead", "Left", "front < 50").text
    edit = add_transition(text, "Left", "Ahead", "turn_done and timer_done")
    d = loads_fsm(edit.text, "m.yaml")
    assert d.initial == "Ahead"
    assert [t.when for t in d.state("Left").transitions] == ["turn_done and timer_done"]
    assert "{when: turn_done and timer_done, to: Ahead}" in edit.text.splitlines()[edit.line]


def test_the_students_own_lines_and_comments_stay():
    text = "# my machine\ninitial: A\nstates:\n  A:   # the start\n    on_enter: [{move: 1}]\n"
    out = add_transition(text, "A", "A", "front < 50: x").text
    assert out.startswith("# my machine\ninitial: A\nstates:\n  A:   # the start\n")
    assert '"front < 50: x"' in out  # quoted: it holds ': '


def test_forms_refuse_what_they_cannot_write():
    with pytest.raises(FormError, match="not a name"):
        add_state("", "2fast")
    with pytest.raises(FormError, match="no state 'B'"):
        add_transition("initial: A\nstates:\n  A: {}\n", "A", "B")
    with pytest.raises(FormError, match="one line"):
        add_state("states: {A: {}}\n", "B")
    with pytest.raises(FormError, match="not an action"):
        add_state("", "A", "fly: 3")


def test_problems_are_placed_at_their_line_and_column():
    checked = check("initial: A\nstates:\n  A:\n    transitions: [{to: Nowhere}]\n")
    assert checked.definition is None
    (p,) = checked.problems
    assert (p.line, "Nowhere" in p.message) == (4, True)


def test_a_draft_saves_in_the_workspace_and_not_past_the_limits(tmp_path):
    files = FileAccess.confined_to(tmp_path / "ws")
    draft = FsmDraft.open(files, "~/mine.yaml")
    assert draft.saved == "" and draft.dirty("x")
    draft.save("initial: A\nstates:\n  A: {}\n")
    assert (tmp_path / "ws" / "mine.yaml").read_text().startswith("initial: A")
    assert not draft.dirty("initial: A\nstates:\n  A: {}\n")
    with pytest.raises(FsmEditError, match="outside your workspace"):
        draft.save("x: 1\n", "/etc/x.yaml")
    with pytest.raises(FsmEditError, match="not saved"):
        draft.save("a: 1\n" * 25_000)
