"""Fused chains (program/fused.py) run every program as its activities' own steps run it:
errors, budgets and stops, Timers, keys, block calls, Joins and loops; deep and hostile
programs load quickly and give no program text to the code made of them."""

from __future__ import annotations

import time

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from tests.program import hostile
from tests.program.builder import ProgramBuilder
from tests.program.graded_programs import right_wall, runaway
from tests.program.ticking import run, seen
from workbench.program import fused
from workbench.program.compiled import compile_program
from workbench.program.interp import FLOW_TICK_STEPS, Limits, ProgramController
from workbench.program.keys import KEY_NUMBERS, parse_key_script
from workbench.program.loader import load_program
from workbench.program.model import ELSE

ROBOT = "Robot/IoT Controller 0"


def both_ways(path, seconds: float, readings=None, keys: str = "", limits=None) -> tuple:
    """What a user sees of the program's run fused and step by step (they must agree)."""
    limits = limits or Limits()
    out = []
    for fuse in (True, False):
        compiled = compile_program(load_program(str(path)))
        c = ProgramController(compiled, parse_key_script(keys), 0.25, limits, fuse=fuse)
        out.append(seen(c, run(c, seconds, readings)))
    assert out[0] == out[1]
    return out[0]


def wobbling(t: float) -> dict[int, float]:
    """Readings that cross every threshold of the test programs now and then."""
    return {1: 5 + (t * 41) % 90, 2: int(t * 0.9) % 2, 3: (t * 17) % 60}


def test_errors_timers_and_fan_outs_agree(tmp_path):
    b = ProgramBuilder()
    b.var("n", "System.Int32")
    b.var("text", "System.String")
    m = b.panel("Main")
    b.robot(m)
    sensor = m.add(23, ROBOT, "1")
    cond = m.add(6, "value > 70", "value > 40 && state.n < 3", "value < 0 || !(value > 9)")
    store = m.add(1, "n")
    word = m.add(3, '"slow"')
    keep = m.add(1, "text")
    bad = m.add(1, "n")  # "slow" is no Int32: an error after the fan-out has gone
    calc = m.add(2, "state.n + value / 10")
    drive = m.add(20, "value / 100", "-0.5", ROBOT, "3", "5")
    wait = m.add(15)
    show = m.add(28, "")
    zero = m.add(2, "1 / (state.n - state.n)")  # division by zero
    b.link(sensor, cond)
    b.link(cond, word, pin=0)
    b.link(word, keep)
    b.link(keep, bad)
    b.link(keep, show)
    b.link(cond, calc, pin=1)
    b.link(calc, store)
    b.link(store, drive)
    b.link(drive, wait)
    b.link(wait, show)
    b.link(cond, zero, pin=2)
    b.link(cond, show, pin=ELSE)
    # a Timer given text, and one of 0 ms
    m.chain(m.add(3, '"later"'), m.add(15))
    m.chain(m.add(3, "0"), m.add(15), m.add(28, ""))
    got = both_ways(b.write(tmp_path / "p.viple"), 8.0, wobbling)
    errors = got[3]
    assert any("is not a number for a Int32" in e for e in errors)
    assert any("division by zero" in e for e in errors)
    assert any("the Timer needs a number of milliseconds" in e for e in errors)
    assert got[6] > 50


def test_a_condition_that_is_no_boolean_and_a_global_of_the_wrong_type_agree(tmp_path):
    b = ProgramBuilder()
    b.var("word", "System.String")
    m = b.panel("Main")
    b.robot(m)
    sensor = m.add(23, ROBOT, "1")
    cond = m.add(6, "state.word > 3", "value", "!value", "value && true", "value == true")
    b.link(sensor, cond)
    for pin in (0, 1, 2, 3, 4, ELSE):
        b.link(cond, m.add(28, ""), pin=pin)
    got = both_ways(b.write(tmp_path / "p.viple"), 1.0, {1: 12})
    assert "cannot compare String with Int32" in got[3][0]


def test_the_work_budgets_and_the_stop_agree(tmp_path):
    got = both_ways(runaway(tmp_path / "r.viple"), 3.0)
    assert "activities in one simulated second" in got[4]
    path = tmp_path / "spin.viple"
    path.write_text(hostile.merge_spin())
    both_ways(path, 2.0)
    # a budget of a tick larger than a flow may run in one tick: flows are counted too
    big = Limits(tick=FLOW_TICK_STEPS * 3, second=10 * FLOW_TICK_STEPS)
    got = both_ways(path, 2.0, limits=big)
    assert got[4] != "None"
    path.write_text(hostile.number_doubling())
    assert "64-bit" in both_ways(path, 2.0)[4]


def test_keys_block_calls_joins_and_loops_agree(tmp_path):
    b = ProgramBuilder()
    b.var("count", "System.Int32")
    m = b.panel("Main")
    twice = b.panel("Twice", inputs=(("times", "System.Int32"),))
    calc = twice.add(2, "value * instance.times")
    b.link(twice.pin_in, calc)
    b.link(calc, twice.pin_out)
    b.robot(m)
    key = m.add(13, str(KEY_NUMBERS["w"]))
    block = m.add(0, "times", "state.count + 2", name="Twice")
    join = m.add(4, "left", "right")
    both = m.add(20, "left / 100.0", "right / 100.0", ROBOT, "3", "5")
    m.chain(key, m.add(3, "21"), block)
    b.link(block, join, in_pin=0)
    thirty = m.add(3, "30")
    b.link(key, thirty)
    b.link(thirty, join, in_pin=1)
    b.link(join, both)
    # a While counting to 5, printing each pass, then a Switch
    loop = m.add(8, "state.count < 5")
    add = m.add(2, "state.count + 1")
    keep = m.add(1, "count")
    end = m.add(10)
    after = m.add(7, "3", "value == 5")
    release = m.add(29)
    m.chain(release, m.add(3, "0"), loop, add, keep, m.add(28, ""), end)
    b.link(end, after)
    b.link(after, m.add(28, ""), pin=1)
    b.link(after, m.add(28, ""), pin=ELSE)
    path = b.write(tmp_path / "p.viple")
    got = both_ways(path, 6.0, wobbling, keys="w@0.5 release@1.2 w@2 release@2.5 w@3")
    assert got[2] and got[6] > 20


def test_a_key_started_right_wall_follower_agrees(tmp_path):
    path = right_wall(tmp_path / "rw.viple", start_key="a")
    got = both_ways(path, 30.0, wobbling, keys="a@0.5 release@0.9")
    assert len(got[0]) > 20


def test_long_chains_deep_ifs_and_long_conditions_load_promptly_and_agree(tmp_path):
    b = ProgramBuilder()
    b.var("n", "System.Int32")
    m = b.panel("Main")
    b.robot(m)
    # 600 Calculates one after another (past a chain's length and a slice)
    steps = [m.add(3, "0")] + [m.add(2, "value + 1") for _ in range(600)] + [m.add(28, "")]
    m.chain(*steps)
    # Ifs nested 60 deep (past a chain's nesting), each a long && of comparisons
    sensor = m.add(23, ROBOT, "1")
    last = sensor
    for depth in range(60):
        test = " && ".join([f"value > {depth % 7}"] * 40)
        cond = m.add(6, test)
        b.link(last, cond, pin=0)
        b.link(cond, m.add(28, ""), pin=ELSE)
        last = cond
    # a condition nested as deep as expressions may be
    deep = m.add(6, "(" * 38 + "value > 1" + ")" * 38)
    b.link(last, deep)
    b.link(deep, m.add(1, "n"))
    path = b.write(tmp_path / "deep.viple")
    start = time.perf_counter()
    ProgramController(compile_program(load_program(path)))
    assert time.perf_counter() - start < 30  # made in well under a second; bounded anyway
    got = both_ways(path, 2.0, wobbling)
    assert "600" in [text for _, text in got[1]]


def test_thousands_of_activities_fuse_within_the_program_budget(tmp_path, monkeypatch):
    made = []
    real = fused._make
    monkeypatch.setattr(fused, "_make", lambda src, helpers: made.append(src) or real(src, helpers))
    b = ProgramBuilder()
    m = b.panel("Main")
    b.robot(m)
    for _ in range(1_200):
        m.chain(m.add(3, "1"), m.add(2, "value + 1"), m.add(6, "value > 1"), m.add(28, ""))
    path = b.write(tmp_path / "many.viple")
    both_ways(path, 0.2)
    fused_activities = sum(len(src.places) for src in made)
    assert 0 < fused_activities <= fused.MAX_FUSED + fused.MAX_CHAIN


def test_no_text_of_the_program_reaches_the_code_made_of_it(tmp_path, monkeypatch):
    made = []
    real = fused._make
    monkeypatch.setattr(fused, "_make", lambda src, helpers: made.append(src) or real(src, helpers))
    evil = '"); import os; os.system("touch pwned"); ("'
    b = ProgramBuilder()
    b.var("__import__", "System.String")
    b.var("exec", "System.Int32")
    m = b.panel("Main")
    b.robot(m)
    sensor = m.add(23, ROBOT, "1")
    cond = m.add(6, 'state.__import__ == "\\"); os.system(1)#" || state.exec > 3')
    b.link(sensor, cond)
    m.chain(m.add(3, '"' + evil.replace('"', "'") + '"'), m.add(1, "__import__"))
    text = m.add(3, "'" + evil + "'")
    b.link(cond, text, pin=0)
    b.link(text, m.add(1, "__import__"))
    b.link(cond, m.add(28, ""), pin=ELSE)
    both_ways(b.write(tmp_path / "evil.viple"), 2.0, wobbling)
    source = "\n".join(line for src in made for line in src.lines)
    assert made and "os" not in source.split() and "system" not in source
    assert "__import__" not in source and "pwned" not in source and "exec" not in source


@pytest.mark.parametrize("name", ["web-wall-following.viple", "right-wall.viple"])
def test_the_shipped_programs_agree_on_the_web_maze_readings(name):
    from pathlib import Path

    path = Path(__file__).resolve().parents[2] / "programs" / name
    got = both_ways(path, 120.0, wobbling)
    assert got[6] > 500


#: parts of the conditions the fuzz test writes: every kind of part a chain writes out as code
#: (value, state.X, literals of each type, comparisons, &&, ||, !) and some it runs by their
#: functions (arithmetic, calls, iif)
_LEAVES = st.sampled_from(
    ["value", "state.n", "state.word", "state.flag", "3", "2.5", '"fwd"', "true", "false",
     "null", "value + 1", "Math.Abs(value)", "iif(state.flag, 1, 2)"]
)  # fmt: skip
_COMPARE = st.sampled_from(["==", "=", "!=", "<>", "<", "<=", ">", ">="])


def _conditions(leaf: st.SearchStrategy[str]) -> st.SearchStrategy[str]:
    compared = st.tuples(leaf, _COMPARE, leaf).map(" ".join)
    return st.recursive(
        st.one_of(compared, leaf),
        lambda inner: st.one_of(
            st.tuples(inner, st.sampled_from(["&&", "||", "and", "or"]), inner).map(
                lambda t: f"({t[0]}) {t[1]} ({t[2]})"
            ),
            inner.map(lambda c: f"!({c})"),
        ),
        max_leaves=8,
    )


@settings(max_examples=60, deadline=None)
@given(
    st.lists(_conditions(_LEAVES), min_size=1, max_size=3),
    st.lists(
        st.one_of(st.integers(-5, 90), st.sampled_from(["fwd", "12", "x", True])),
        min_size=4,
        max_size=4,
    ),
)
def test_any_condition_runs_the_same_fused_errors_included(tmp_path_factory, conditions, values):
    """Whatever an If's conditions are and whatever the sensor reports, the chain's code for
    them gives the same branches, and the same errors at the same times, as the conditions'
    functions."""
    b = ProgramBuilder()
    b.var("n", "System.Int32")
    b.var("word", "System.String")
    b.var("flag", "System.Boolean")
    m = b.panel("Main")
    b.robot(m)
    m.chain(m.add(3, '"fwd"'), m.add(1, "word"))
    sensor = m.add(25, ROBOT, "1")
    cond = m.add(6, *conditions)
    b.link(sensor, cond)
    for pin in (*range(len(conditions)), ELSE):
        b.link(cond, m.add(28, ""), pin=pin)
    b.link(sensor, m.add(1, "n"))
    path = b.write(tmp_path_factory.mktemp("fuzz") / "p.viple")
    both_ways(path, 1.1, lambda t: {1: values[int(t * 4) % 4]})


def test_known_messages_and_literal_powers_are_worked_out_once_and_agree(tmp_path):
    """A Data's constant stored by a Variable, a Timer of a known wait and a Robot Drive of two
    literal powers run as values made when the chain is made; the ones that would raise (a
    text for an Int32, a Timer of text, a power of text) still raise as the steps do."""
    b = ProgramBuilder()
    b.var("n", "System.Int32")
    b.var("word", "System.String")
    m = b.panel("Main")
    b.robot(m)
    sensor = m.add(23, ROBOT, "1")
    cond = m.add(6, "value > 50", "value > 20")
    b.link(sensor, cond)
    # known all along: 7 stored as text, a drive of -0.2 and 0.4, a Timer of 250 ms
    m.chain(m.add(3, "7"), m.add(1, "word"), m.add(20, "-0.2", "0.4", ROBOT, "3", "5"))
    fast = m.add(3, "250")
    b.link(cond, fast, pin=0)
    m.chain(fast, m.add(1, "n"), m.add(20, "0.5", "--0.5", ROBOT, "3", "5"), m.add(15))
    # known, but each goes wrong: "abc" is no Int32, a Timer of text, a power of text
    wrong = m.add(3, '"abc"')
    b.link(cond, wrong, pin=1)
    b.link(wrong, m.add(1, "n"))
    b.link(wrong, m.add(15))
    b.link(wrong, m.add(20, '"fast"', "0.5", ROBOT, "3", "5"))
    b.link(cond, m.add(20, '-"a"', "0.5", ROBOT, "3", "5"), pin=ELSE)
    got = both_ways(b.write(tmp_path / "p.viple"), 6.0, lambda t: {1: (t * 37) % 80})
    commands, errors = got[0], got[3]
    assert {(c.left, c.right) for c in commands} >= {(-0.2, 0.4), (0.5, 0.5)}
    assert any("is not a number for a Int32" in e for e in errors)
    assert any("the Timer needs a number of milliseconds" in e for e in errors)
    assert any("the left power must be a number" in e for e in errors)
    assert any("- needs a number" in e for e in errors)
    assert got[5]["word"] == "7"


def test_a_literal_drive_makes_its_command_once(tmp_path):
    """The chain of a Robot Drive of two literal powers sends the one command it made when it
    was made, at every pass (the same frozen value each time)."""
    b = ProgramBuilder()
    m = b.panel("Main")
    b.robot(m)
    sensor = m.add(23, ROBOT, "1")
    b.link(sensor, m.add(20, "0.3", "-0.3", ROBOT, "3", "5"))
    compiled = compile_program(load_program(str(b.write(tmp_path / "p.viple"))))
    c = ProgramController(compiled, (), 0.25)
    commands = run(c, 2.0, {1: 10})
    assert len(commands) == 8
    assert all(cmd is commands[0] for cmd in commands)
    assert (commands[0].left, commands[0].right) == (0.3, -0.3)
