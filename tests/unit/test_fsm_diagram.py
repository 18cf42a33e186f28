"""The layered diagram of a machine: layers from the initial state, boxes and arrows placed
where the front end highlights them, within the width asked for, in ASCII or Unicode."""

from pathlib import Path

from workbench.fsm.diagram import layers_of, layout, state_notes
from workbench.fsm.yaml_file import load_fsm, loads_fsm

RIGHT_WALL = Path(__file__).resolve().parents[2] / "workbench/fsm/algorithms/right-wall.yaml"

SMALL = """\
initial: A
states:
  Lone: {}
  B:
    transitions: [{to: B, when: x > 1}, {to: A}]
  A:
    on_enter: [{move: 1}]
    transitions: [{to: B}]
sensors:
  x: {kind: distance, mount: front, port: 1}
"""


def test_layers_follow_the_transitions_from_the_initial_state():
    d = loads_fsm(SMALL, "s.yaml")
    assert layers_of(d) == [("A", 0), ("B", 1), ("Lone", -1)]
    assert layers_of(load_fsm(RIGHT_WALL))[:3] == [
        ("Forward", 0), ("BesideOpening", 1), ("TurningLeft", 1)]  # fmt: skip


def test_boxes_and_arrows_are_where_the_diagram_says():
    d = loads_fsm(SMALL, "s.yaml")
    g = layout(d, 40, unicode=False, notes=state_notes(d))
    first, _last = g.boxes["A"]
    assert g.lines[first].startswith("+-") and "A  (start)" in g.lines[first + 1]
    assert "move 1" in g.lines[first + 2]
    a, b = g.arrows[("B", 0)]
    assert "x > 1" in g.lines[a] and g.lines[b].endswith("-> B @")
    a, b = g.arrows[("B", 1)]
    assert g.lines[b].endswith("-> A ^") and "always" in g.lines[a]
    assert "not reached from the start:" in g.text()
    assert "(final: no transitions)" in g.text()
    assert all(ord(c) < 128 for c in g.text())


def test_a_narrow_pane_gets_every_line_within_its_width():
    g = layout(load_fsm(RIGHT_WALL), 30, unicode=True, notes=state_notes(load_fsm(RIGHT_WALL)))
    assert g.width <= 30
    assert "┌" in g.text() and "▶" in g.text()
    for a, b in g.arrows.values():
        assert b >= a and g.lines[b].strip()
    assert set(g.boxes) == {"Forward", "BesideOpening", "TurningRight", "TurnedRight",
                            "TurningLeft"}  # fmt: skip
