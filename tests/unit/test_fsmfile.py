"""Reading FSM files: a good file runs, a bad one reports every problem at file:line:column."""

import re
import textwrap
from pathlib import Path

import pytest

from workbench.fsm.machine import FsmController, ParameterError, StopAction
from workbench.fsm.yaml_file import FsmFileError, load_fsm, loads_fsm, parse_param_overrides
from workbench.sim.commands import MoveAtPower, TurnByDegrees

DOCS = Path(__file__).resolve().parents[2] / "docs" / "fsm-format.md"

GOOD = """\
name: tiny
description: Drive, turn left at walls.
sensors:
  front: {kind: distance, mount: front, port: 2}
parameters:
  limit:
    default: {unity: 0.9, web: 25, erobotic: 50}
    min: 0
    max: 500
    description: Turn below this.
variables:
  turns: 0
initial: Drive
states:
  Drive:
    on_enter:
      - move: 1
    transitions:
      - when: front < limit
        to: Turn
  Turn:
    on_enter:
      - turn: -90
    transitions:
      - when: turn_done
        to: Drive
        set: {turns: turns + 1}
"""


def problems(text, name="bad.yaml"):
    with pytest.raises(FsmFileError) as info:
        loads_fsm(text, name)
    return [str(p) for p in info.value.problems]


def edit(old, new):
    assert old in GOOD
    return GOOD.replace(old, new)


def test_a_good_file_loads_and_runs():
    defn = loads_fsm(GOOD, "tiny.yaml")
    assert defn.name == "tiny" and defn.initial == "Drive"
    assert [s.name for s in defn.states] == ["Drive", "Turn"]
    assert defn.parameter("limit").defaults == {"unity": 0.9, "web": 25.0, "erobotic": 50.0}
    ctl = FsmController(defn, {}, "web")
    assert ctl.start(0) == [MoveAtPower(1.0)]
    assert ctl.tick(0.1, {"front": 20.0}) == [TurnByDegrees(-90)]
    ctl.tick(0.2, {"front": 20.0}, frozenset({"turn_done"}))
    assert ctl.variables == {"turns": 1}


def test_the_documented_example_loads_and_runs():
    block = re.search(r"```yaml\n(name: bump-and-turn.*?)```", DOCS.read_text(), re.S)
    defn = loads_fsm(block.group(1), "example.yaml")
    ctl = FsmController(defn, {}, "erobotic")
    assert ctl.start(0) == [MoveAtPower(1.0)]
    assert ctl.tick(1, {"front": 40.0}) == [MoveAtPower(-0.5)]
    assert ctl.tick(1.5, {"front": 60.0}) == [TurnByDegrees(-90)]
    assert ctl.tick(3, {"front": 60.0}, frozenset({"turn_done"})) == [MoveAtPower(1.0)]
    assert ctl.variables == {"turns": 1}


def test_name_defaults_to_the_file_name(tmp_path):
    path = tmp_path / "my-walker.yaml"
    path.write_text(GOOD.replace("name: tiny\n", ""))
    assert load_fsm(path).name == "my-walker"


def test_yaml_booleans_and_omitted_guards_work():
    text = edit(
        "      - when: turn_done\n        to: Drive", "      - when: yes\n        to: Drive"
    )
    ctl = FsmController(loads_fsm(text), {}, "unity")
    ctl.start(0)
    ctl.tick(1, {"front": 0.1})
    assert ctl.tick(2, {"front": 0.1}) == [MoveAtPower(1.0)]
    stop = loads_fsm(edit("      - move: 1\n", "      - stop\n      - stop:\n"))
    assert stop.state("Drive").on_enter == (StopAction(), StopAction())


# -- every error path, with its position ----------------------------------------------------


def test_yaml_syntax_error_has_line_and_column():
    text = edit("    min: 0\n", "    min: 0\n   max: [1\n")
    (msg,) = problems(text)
    assert msg.startswith("bad.yaml:9:4:") and "YAML syntax" in msg


def test_tabs_get_a_hint():
    (msg,) = problems("name: x\nstates:\n\tA: {}\n")
    assert "bad.yaml:3:1: YAML syntax" in msg and "indent with spaces, not tabs" in msg


def test_empty_file_and_non_mapping_file():
    assert problems("") == ["bad.yaml:1:1: the file is empty (hint: start with name: and states:)"]
    assert problems("- a\n- b\n") == [
        "bad.yaml:1:1: an FSM file must be a mapping with name:, initial: and states:"
    ]


def test_unknown_state_in_to_points_at_the_value():
    (msg,) = problems(edit("        to: Turn\n", "        to: Trun\n"))
    assert msg == "bad.yaml:20:13: unknown state 'Trun' in to: (hint: did you mean 'Turn'?)"


def test_undefined_name_in_a_guard_points_into_the_expression():
    (msg,) = problems(edit("when: front < limit", "when: front < limt"))
    assert msg == "bad.yaml:19:23: unknown name 'limt' (hint: did you mean 'limit'?)"
    (quoted,) = problems(edit("when: front < limit", "when: 'front < limt'"))
    assert quoted.startswith("bad.yaml:19:24: unknown name 'limt'")


def test_undefined_names_in_actions_and_variables():
    text = edit("      - move: 1\n", "      - move: speed\n").replace("turns: 0", "turns: front")
    assert problems(text) == [
        "bad.yaml:12:10: unknown name 'front' (hint: known names: limit)",
        "bad.yaml:17:15: unknown name 'speed' (hint: known names: front, limit, "
        "timer_done, turn_done, turns)",
    ]


def test_bad_expressions_and_refused_constructs():
    text = edit("when: front < limit", "when: front < limit &&").replace(
        "set: {turns: turns + 1}", "set: {turns: __import__('os')}"
    )
    msgs = problems(text)
    assert msgs[0].startswith("bad.yaml:19:") and "bad syntax" in msgs[0]
    assert "write 'and' / 'or' instead of && / ||" in msgs[0]
    assert msgs[1].startswith("bad.yaml:27:22: unknown function '__import__'")


def test_a_tag_instead_of_not_gets_a_hint():
    (msg,) = problems(edit("when: turn_done", "when: !turn_done"))
    assert msg.startswith("bad.yaml:25:") and "write 'not x' instead of '!x'" in msg


def test_unknown_action_and_two_actions_in_one_item():
    text = edit(
        "      - turn: -90\n", "      - trun: -90\n      - {move: 1, timer: 2}\n      - go\n"
    )
    assert problems(text) == [
        "bad.yaml:23:9: unknown action 'trun' (hint: did you mean 'turn'? actions: wheels, "
        "motor, move, turn, stop, set, timer)",
        "bad.yaml:24:9: put each action in its own list item (hint: e.g. '- move: 1.0' then "
        "'- timer: 2' on the next line)",
        "bad.yaml:25:9: unknown action 'go' (hint: actions: wheels, motor, move, turn, stop, set, "
        "timer)",
    ]


def test_action_arguments_are_checked():
    text = edit(
        "      - move: 1\n",
        "      - wheels: [0.5]\n"
        "      - motor: {wheel: middle, power: 0.3}\n"
        "      - motor: {wheel: left}\n"
        "      - stop: 3\n"
        "      - set: {limit: 2, front: 1, nothing: 3}\n",
    )
    assert problems(text) == [
        "bad.yaml:17:17: wheels takes two powers: [left, right] (hint: e.g. wheels: [0.5, 0.5])",
        "bad.yaml:18:24: unknown wheel 'middle' (hint: use left or right)",
        "bad.yaml:19:16: motor has no power (hint: e.g. motor: {wheel: left, power: 0.3})",
        "bad.yaml:20:15: stop takes no value (hint: write '- stop')",
        "bad.yaml:21:15: 'limit' is not a variable (hint: only variables can be assigned; "
        "sensors, parameters and events cannot)",
        "bad.yaml:21:25: 'front' is not a variable (hint: only variables can be assigned; "
        "sensors, parameters and events cannot)",
        "bad.yaml:21:35: 'nothing' is not a variable (hint: declare it under variables: "
        "(nothing: 0))",
    ]


def test_missing_initial_and_unknown_initial():
    assert problems(GOOD.replace("initial: Drive\n", "")) == [
        "bad.yaml:1:1: no initial: state (hint: add e.g. initial: Drive)"
    ]
    assert problems(GOOD.replace("initial: Drive", "initial: drive")) == [
        "bad.yaml:13:10: the initial state 'drive' is not defined (hint: did you mean 'Drive'?)"
    ]


def test_missing_or_empty_states():
    text = GOOD[: GOOD.index("states:")]
    assert "no states: section" in problems(text)[0]
    assert problems(text + "states:\n") == [
        "bad.yaml:14:1: no states are defined (hint: add at least one state)"
    ]


def test_wrong_types_are_reported_where_they_are():
    text = (
        GOOD.replace("port: 2}", "port: two}")
        .replace("default: {unity: 0.9, web: 25, erobotic: 50}", "default: {unity: near}")
        .replace("    on_enter:\n      - move: 1\n", "    on_enter: move\n")
        .replace(
            "    transitions:\n      - when: turn_done\n", "    transitions:\n      - when: 1\n"
        )
        .replace("        to: Drive\n", "")
    )
    assert problems(text) == [
        "bad.yaml:4:47: port must be a number, not 'two'",
        "bad.yaml:7:22: default of limit (unity) must be a number, not 'near'",
        "bad.yaml:16:15: on_enter must be a list of '- ...' items (hint: e.g. on_enter: "
        "[{move: 1.0}, {timer: 2}])",
        "bad.yaml:24:9: this transition has no to: state (hint: add e.g. to: Forward)",
    ]


def test_unknown_keys_get_a_suggestion():
    text = edit(
        "      - when: front < limit\n        to: Turn",
        "      - if: front < limit\n        to: Turn",
    )
    text = text.replace("initial: Drive", "initial: Drive\ninitail: Drive")
    assert problems(text) == [
        "bad.yaml:14:1: unknown key 'initail' in the file (hint: did you mean 'initial'?)",
        "bad.yaml:20:9: unknown key 'if' in a transition (hint: did you mean 'when'?)",
    ]


def test_duplicate_keys_are_reported_not_silently_dropped():
    text = GOOD + "  Drive:\n    on_enter: [stop]\n"
    assert problems(text) == [
        "bad.yaml:28:3: 'Drive' appears twice in states (first on line 15) "
        "(hint: remove or rename one)"
    ]


def test_sensor_problems():
    text = GOOD.replace(
        "  front: {kind: distance, mount: front, port: 2}\n",
        "  front: {kind: sonar, mount: top, port: 2}\n"
        "  right: {kind: distance, mount: right, port: 2}\n"
        "  left: {kind: distance, port: 3}\n"
        "  back: {kind: touch, mount: back, port: {unity: 4, web: 4}}\n",
    )
    assert problems(text) == [
        "bad.yaml:4:17: unknown sensor kind 'sonar' (hint: use one of distance, touch)",
        "bad.yaml:4:31: unknown mount 'top' (hint: use one of front, right, back, left)",
        "bad.yaml:5:47: port 2 (unity, web, erobotic) is also used by sensor 'front' (hint: "
        "give each sensor its own port)",
        "bad.yaml:6:9: sensor left has no mount: (hint: e.g. front: {kind: distance, mount: "
        "front, port: 2})",
        "bad.yaml:7:42: no port for profile erobotic (hint: give one port number, or one per "
        "profile)",
    ]


def test_a_port_must_be_a_whole_number_in_range():
    assert problems(GOOD.replace("port: 2}", "port: 1.5}")) == [
        "bad.yaml:4:47: port 1.5 (unity, web, erobotic) is not a whole number from 0 to 99"
    ]
    text = GOOD.replace("port: 2}", "port: {unity: 2, web: 200, erobotic: 2, lego: 1}}")
    assert problems(text) == [
        "bad.yaml:4:63: port 200 (web) is not a whole number from 0 to 99",
        "bad.yaml:4:81: unknown profile 'lego' (hint: use one of unity, web, erobotic)",
    ]


def test_names_must_be_distinct_and_not_reserved():
    text = edit("  turns: 0\n", "  turns: 0\n  front: 1\n  turn_done: 0\n  2fast: 0\n")
    assert problems(text) == [
        "bad.yaml:13:3: 'front' is already declared under sensors (hint: rename one)",
        "bad.yaml:14:3: 'turn_done' is reserved (hint: choose another name)",
        "bad.yaml:15:3: '2fast' cannot be used as a name (hint: use letters, digits and _)",
    ]


def test_parameter_ranges_are_checked():
    text = edit("    min: 0\n    max: 500\n", "    min: 30\n    max: 20\n")
    assert problems(text) == [
        "bad.yaml:7:22: default 0.9 (unity) is below min 30",
        "bad.yaml:7:32: default 25 (web) is below min 30",
        "bad.yaml:7:46: default 50 (erobotic) is above max 20",
        "bad.yaml:8:10: min 30 is above max 20 (hint: swap them)",
    ]
    assert problems(edit("web: 25,", "webb: 25,")) == [
        "bad.yaml:7:27: unknown profile 'webb' (hint: use one of unity, web, erobotic)"
    ]


def test_all_problems_come_in_file_order():
    text = (
        GOOD.replace("to: Turn", "to: Tunr")
        .replace("port: 2}", "port: 2, colour: red}")
        .replace("- turn: -90", "- turn: left")
    )
    msgs = problems(text)
    lines = [int(m.split(":")[1]) for m in msgs]
    assert lines == sorted(lines) and len(msgs) == 3
    assert "unknown key 'colour'" in msgs[0]
    assert "unknown state 'Tunr'" in msgs[1]
    assert "unknown name 'left'" in msgs[2]


def test_an_unreadable_file_is_an_fsm_file_error(tmp_path):
    with pytest.raises(FsmFileError, match=r"missing.yaml: cannot read the file"):
        load_fsm(tmp_path / "missing.yaml")


def test_errors_show_the_file_name(tmp_path):
    path = tmp_path / "walker.yaml"
    path.write_text(edit("to: Turn", "to: Tunr"))
    with pytest.raises(FsmFileError, match=re.escape(f"{path}:20:13: unknown state 'Tunr'")):
        load_fsm(path)


# -- NAME=VALUE parameter overrides ------------------------------------------------------


@pytest.fixture
def tiny():
    return loads_fsm(GOOD, "tiny.yaml")


def test_overrides_are_parsed(tiny):
    assert parse_param_overrides(tiny, ["limit=40", " limit = 45.5 "]) == {"limit": 45.5}
    assert parse_param_overrides(tiny, []) == {}


@pytest.mark.parametrize(
    ("item", "message"),
    [
        ("limt=3", "tiny has no parameter 'limt' (did you mean 'limit'?)"),
        ("speed=3", "tiny has no parameter 'speed' (parameters: limit)"),
        ("limit=near", "parameter limit: 'near' is not a number"),
        ("limit=inf", "parameter limit: 'inf' is not a finite number"),
        ("limit=-1", "parameter limit=-1 is below its minimum 0"),
        ("limit=501", "parameter limit=501 is above its maximum 500"),
        ("limit", "parameter 'limit' must be written NAME=VALUE, e.g. limit=VALUE"),
        ("=3", "must be written NAME=VALUE"),
    ],
)
def test_bad_overrides_are_refused_with_the_reason(tiny, item, message):
    with pytest.raises(ParameterError) as info:
        parse_param_overrides(tiny, [item])
    assert message in str(info.value)


def test_every_bad_override_is_listed(tiny):
    with pytest.raises(ParameterError) as info:
        parse_param_overrides(tiny, ["limit=x", "nope=1"])
    assert len(str(info.value).splitlines()) == 2


def test_loader_source_is_remembered(tmp_path):
    path = tmp_path / "w.yaml"
    path.write_text(textwrap.dedent(GOOD))
    assert load_fsm(path).source == str(path)
