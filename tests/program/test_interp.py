"""Running VIPLE programs: each semantic rule on a small program written for the test."""

from __future__ import annotations

from pathlib import Path

import pytest

from tests.program.builder import ProgramBuilder
from tests.program.ticking import TICK, run, seen
from workbench.program import kinds as K
from workbench.program.compiled import compile_program
from workbench.program.interp import MAPPED_RUNS, PREPARED, RUNS, SENSES, ProgramController
from workbench.program.keys import KeyScriptError, parse_key_script
from workbench.program.kinds import parse_kind_map
from workbench.program.loader import load_program
from workbench.program.model import ELSE
from workbench.program.problems import ProgramError
from workbench.sim.commands import MotorPower, MoveAtPower, TurnByDegrees, WheelPowers


def controller(b: ProgramBuilder, tmp_path, keys: str = "", kinds=None) -> ProgramController:
    path = b.write(tmp_path / "p.viple")
    return ProgramController(compile_program(load_program(path, kinds)), parse_key_script(keys))


def texts(c: ProgramController) -> list[str]:
    return [p.text for p in c.printed]


def test_data_without_input_starts_and_fans_out_to_every_target(tmp_path):
    b = ProgramBuilder()
    main = b.panel("Main")
    data = main.add(3, "7")
    calc = main.add(2, "value * 2")
    p1, p2 = main.add(28, ""), main.add(28, "")
    b.link(data, calc)
    b.link(data, p1)
    b.link(calc, p2)
    c = controller(b, tmp_path)
    run(c, 0.1)
    assert sorted(texts(c)) == ["14", "7"]


def test_if_takes_the_first_true_condition_else_the_else_pin(tmp_path):
    b = ProgramBuilder()
    main = b.panel("Main")
    b.robot(main)
    sensor = main.add(23, "Robot/IoT Controller 0", "1")
    cond = main.add(6, "value > 10", "value > 5", "value > 0")
    outs = [main.add(2, f'"pin {k}"') for k in range(3)]
    other = main.add(2, '"else"')
    prints = [main.add(28, "") for _ in range(4)]
    b.link(sensor, cond)
    for k, out in enumerate(outs):
        b.link(cond, out, pin=k)
    b.link(cond, other, pin=ELSE)
    for src, dst in zip([*outs, other], prints, strict=True):
        b.link(src, dst)
    c = controller(b, tmp_path)
    values = iter([20, 7, 3, -1])
    run(c, 0.2, lambda t: {1: next(values)})
    assert texts(c) == ["pin 0", "pin 1", "pin 2", "else"]


def test_merge_loop_counts_and_the_variable_is_global(tmp_path):
    b = ProgramBuilder()
    b.var("n")
    main = b.panel("Main")
    start = main.add(3, "0")
    merge = main.add(5)
    var = main.add(1, "n")
    cond = main.add(6, "state.n < 5")
    calc = main.add(2, "value + 1")
    show = main.add(28, "")
    main.chain(start, merge, var, cond, calc, merge)
    b.link(cond, show, pin=ELSE)
    c = controller(b, tmp_path)
    run(c, 0.1)
    assert texts(c) == ["5"] and c.variables == {"n": 5}


def test_join_waits_for_every_input_and_names_its_parts(tmp_path):
    b = ProgramBuilder()
    main = b.panel("Main")
    b.robot(main)
    left = main.add(13, "0")  # a
    right = main.add(13, "3")  # d
    join = main.add(4, "leftPower", "rightPower")
    drive = main.add(20, "leftPower", "rightPower", "Robot/IoT Controller 0", "3", "5")
    lval, rval = main.add(3, "0.25"), main.add(3, "-0.5")
    b.link(left, lval)
    b.link(right, rval)
    b.link(lval, join, in_pin=0)
    b.link(rval, join, in_pin=1)
    b.link(join, drive)
    c = controller(b, tmp_path, keys="a@0.1 d@0.5")
    commands = run(c, 0.3)
    assert commands == []  # one input alone does not pass the Join
    commands = [cmd for i in range(7, 13) for cmd in c.tick(i * TICK, {}, frozenset())]
    assert commands == [WheelPowers(0.25, -0.5)]


def test_a_busy_while_never_starves_other_flows(tmp_path):
    b = ProgramBuilder()
    b.var("go", "System.Boolean")
    main = b.panel("Main")
    start = main.add(3, "1")
    loop = main.add(8, "!state.go")
    end = main.add(10, "")
    done = main.add(2, '"left the loop"')
    show = main.add(28, "")
    main.chain(start, loop, end, done, show)
    key = main.add(13, "18")  # s
    true = main.add(3, "true")
    var = main.add(1, "go")
    main.chain(key, true, var)
    c = controller(b, tmp_path, keys="s@1.0")
    run(c, 0.9)
    assert texts(c) == [] and c.steps < 2_000  # the idle loop waits for a change
    run_more = [c.tick(t, {}, frozenset()) for t in (1.0, 1.05)]
    assert run_more and texts(c) == ["left the loop"]


def test_a_timer_sleeps_in_its_own_flow_only(tmp_path):
    b = ProgramBuilder()
    main = b.panel("Main")
    start = main.add(3, "500")
    timer = main.add(15, "")
    late = main.add(2, '"after 500 ms"')
    p1 = main.add(28, "")
    main.chain(start, timer, late, p1)
    b.robot(main)
    sensor = main.add(23, "Robot/IoT Controller 0", "2")
    p2 = main.add(28, "")
    b.link(sensor, p2)
    c = controller(b, tmp_path)
    run(c, 0.7, {2: 9})
    times = {p.text: p.time for p in c.printed}
    assert times["after 500 ms"] == pytest.approx(0.5)
    assert sum(p.text == "9" for p in c.printed if p.time < 0.5) == 9


def test_block_parameters_output_pin_and_event_pin(tmp_path):
    b = ProgramBuilder()
    main = b.panel("Main")
    straight = b.panel("Twice", inputs=(("times", "System.Int32"),))
    calc = straight.add(2, "value * instance.times")
    b.link(straight.pin_in, calc)
    b.link(calc, straight.pin_out)
    b.link(calc, straight.pin_event)
    start = main.add(3, "21")
    block = main.add(0, "times", "1 + 1", name="Twice")
    out = main.add(2, '"output " + value')
    p1 = main.add(28, "")
    main.chain(start, block, out, p1)
    event = main.add(33, "Twice")
    p2 = main.add(2, '"event " + value')
    p3 = main.add(28, "")
    main.chain(event, p2, p3)
    kinds = parse_kind_map({"kinds": {33: {"activity": "custom-event", "value": 0}}}, "k.yaml")
    c = controller(b, tmp_path, kinds=kinds)
    run(c, 0.1)
    assert sorted(texts(c)) == ["event 42", "output 42"]
    assert [f.what for f in c.fired] == ["custom event Twice"]


def test_touch_fires_on_press_only_and_key_release_stops(tmp_path):
    b = ProgramBuilder()
    main = b.panel("Main")
    b.robot(main)
    touch = main.add(22, "Robot/IoT Controller 0", "1")
    p = main.add(28, "")
    b.link(touch, p)
    key = main.add(13, "22")
    go = main.add(20, "0.5", "0.5", "Robot/IoT Controller 0", "3", "5")
    b.link(key, go)
    release = main.add(29, "")
    stop = main.add(20, "0", "0", "Robot/IoT Controller 0", "3", "5")
    b.link(release, stop)
    c = controller(b, tmp_path, keys="w@0.1 release@0.3")
    pressed = lambda t: {1: 1 if 0.15 < t < 0.4 else 0}  # noqa: E731
    commands = run(c, 0.5, pressed)
    assert texts(c) == ["1"]
    assert commands == [WheelPowers(0.5, 0.5), WheelPowers(0.0, 0.0)]
    assert [f.what for f in c.fired] == ["key w", "touch 1", "key release"]


def test_mapped_move_at_power_uses_the_message(tmp_path):
    b = ProgramBuilder()
    main = b.panel("Main")
    b.robot(main)
    start = main.add(3, "0.8")
    move = main.add(47, "Robot/IoT Controller 0")
    b.link(start, move)
    kinds = parse_kind_map({"kinds": {47: "move-at-power"}}, "k.yaml")
    c = controller(b, tmp_path, kinds=kinds)
    assert run(c, 0.1) == [MoveAtPower(0.8)]


@pytest.mark.parametrize(
    ("activity", "sent"),
    [
        ({"activity": "turn-by-degrees", "value": 0}, [TurnByDegrees(-90.0)]),
        ("motor-left", [MotorPower("left", 0.4)]),
        ("motor-right", [MotorPower("right", 0.4)]),
        ("ignore", []),
    ],
)
def test_each_mapped_service_sends_its_command_and_passes_the_message_on(tmp_path, activity, sent):
    b = ProgramBuilder()
    main = b.panel("Main")
    b.robot(main)
    start = main.add(3, "0.4")
    service = main.add(48, "-45 * 2")
    p = main.add(28, "")
    main.chain(start, service, p)
    kinds = parse_kind_map({"kinds": {48: activity}}, "k.yaml")
    c = controller(b, tmp_path, kinds=kinds)
    assert run(c, 0.1) == sent
    assert texts(c) == ([] if activity == "ignore" else ["0.4"])


def test_every_activity_kind_a_program_may_hold_has_a_handler():
    assert set(RUNS) | set(PREPARED) == set(K.KNOWN) and not set(RUNS) & set(PREPARED)
    assert set(MAPPED_RUNS) == set(K.MAPPABLE)
    assert set(SENSES) == {K.TOUCH, K.DISTANCE, K.OTHER_SENSOR, K.RAW_SENSOR}


def test_runtime_errors_name_the_activity_and_end_only_that_flow(tmp_path):
    b = ProgramBuilder()
    main = b.panel("Main")
    start = main.add(3, '"text"')
    calc = main.add(2, "value * 2")
    main.chain(start, calc)
    other = main.add(3, '"still here"')
    p = main.add(28, "")
    main.chain(other, p)
    c = controller(b, tmp_path)
    run(c, 0.1)
    assert texts(c) == ["still here"]
    assert f"activity {calc} (Calculate): column 7: * needs numbers" in str(c.errors[0])


def test_compile_problems_name_activity_value_and_column(tmp_path):
    b = ProgramBuilder()
    main = b.panel("Main")
    bad = main.add(2, "value +")
    ghost = main.add(6, "state.nobody > 1")
    code = main.add(44, "Sum", "public class Sum { }")
    path = b.write(tmp_path / "p.viple")
    with pytest.raises(ProgramError) as info:
        compile_program(load_program(path))
    found = [str(p) for p in info.value.problems]
    assert found[0] == (
        f"{path}: panel Main: activity {bad} (kind 2, Calculate): Values[0] 'value +': "
        "expected a value but found the end (column 8)"
    )
    assert any(f"activity {ghost} (kind 6, If): Values[0] reads state.nobody" in p for p in found)
    assert any(f"activity {code} (kind 44, Code Activity): the C# class 'Sum'" in p for p in found)


def test_the_sensor_json_code_activity_runs_as_a_builtin(tmp_path):
    body = (
        "public class Parse : CodeUtilities.CodeBase { public override void Execute() {"
        ' var o = JObject.Parse((string)Input); Output = o["sensors"][0]["value"]; } }'
    )
    b = ProgramBuilder()
    main = b.panel("Main")
    b.robot(main)
    raw = main.add(52, "Robot/IoT Controller 0", "-1")
    code = main.add(44, "Parse", body)
    p = main.add(28, "")
    main.chain(raw, code, p)
    c = controller(b, tmp_path)
    run(c, 0.05, {4: 12.5})
    assert texts(c) == ["12.5"]


def test_key_scripts():
    events = parse_key_script("release@3 w@0.5 a+d@4")
    assert [(e.time, sorted(e.keys)) for e in events] == [
        (0.5, ["w"]),
        (3.0, []),
        (4.0, ["a", "d"]),
    ]
    with pytest.raises(KeyScriptError, match="'x1' is not a key"):
        parse_key_script("x1@2")
    with pytest.raises(KeyScriptError, match="must be KEY@SECONDS"):
        parse_key_script("w")


def test_a_join_inside_a_block_call_goes_with_the_call(tmp_path):
    """A call whose Join got only one of its inputs leaves nothing behind once it ends."""
    import gc

    from workbench.program.interp import Frame

    b = ProgramBuilder()
    main = b.panel("Main")
    half = b.panel("Half")
    join = half.add(4, "a", "b")
    sometimes = half.add(6, "value > 100")  # never true: the second input never comes
    b.link(half.pin_in, join, in_pin=0)
    b.link(half.pin_in, sometimes)
    b.link(sometimes, join, in_pin=1)
    b.link(join, half.pin_out)
    b.link(half.pin_in, half.pin_out)
    key = main.add(13, "22")
    data = main.add(3, "1")
    block = main.add(0, name="Half")
    p = main.add(28, "")
    main.chain(key, data, block, p)
    script = " ".join(f"w@{0.1 * i:.1f} release@{0.1 * i + 0.05:.2f}" for i in range(1, 101))
    c = controller(b, tmp_path, keys=script)
    run(c, 10.5)
    assert len(texts(c)) == 100  # every call ran and came out of its output pin
    gc.collect()
    assert [o for o in gc.get_objects() if isinstance(o, Frame) and o.block is not None] == []
    assert c._joins == {}


def test_typed_keys_hold_while_repeating_and_release_after_a_quiet_gap():
    from workbench.program.keys import RELEASE_GAP, TypedKeys, typed_events

    typed = TypedKeys()
    assert [e.keys for e in typed.press("w", 1.0)] == [frozenset({"w"})]
    assert typed.press("w", 1.5) == []  # the key repeating: still held
    assert typed.due(1.5 + RELEASE_GAP - 0.01) is None
    release = typed.due(1.5 + RELEASE_GAP)
    assert release is not None and release.release and release.time == 1.5 + RELEASE_GAP
    events = typed.press("a", 5.0) + typed.press("d", 5.1)  # another key: release, then press
    assert [(e.time, sorted(e.keys)) for e in events] == [(5.0, ["a"]), (5.1, []), (5.1, ["d"])]
    script = parse_key_script("w@0.5 w@0.6 w@0.7 d@3")
    assert [(e.time, sorted(e.keys)) for e in typed_events(script, until=10)] == [
        (0.5, ["w"]),
        (0.7 + RELEASE_GAP, []),
        (3.0, ["d"]),
        (3.0 + RELEASE_GAP, []),
    ]
    with pytest.raises(KeyScriptError, match="type one key an item"):
        typed_events(parse_key_script("w+d@1"), until=10)


def test_print_line_writes_reals_as_viple_does(tmp_path):
    b = ProgramBuilder()
    main = b.panel("Main")
    main.chain(main.add(3, "0.1"), main.add(2, "value + 0.2"), main.add(28, ""))
    main.chain(main.add(3, "1E+21"), main.add(28, ""))
    main.chain(main.add(3, "2"), main.add(2, "value / 3.0"), main.add(28, ""))
    b.var("Ratio", "System.String")
    main.chain(main.add(3, "0.7"), main.add(2, "value * 3"), main.add(1, "Ratio"),
               main.add(2, '"ratio " + state.Ratio'), main.add(28, ""))  # fmt: skip
    c = controller(b, tmp_path)
    run(c, 0.1)
    assert sorted(texts(c)) == ["0.3", "0.666666666666667", "1E+21", "ratio 2.1"]


def test_a_tick_with_nothing_due_does_nothing_and_the_report_and_the_timer_ticks_do(tmp_path):
    """Between two sensor reports, with no Timer ending and no flow ready, a tick sends
    nothing; the tick at the report fires the sensor, the tick at the Timer's end goes on."""
    b = ProgramBuilder()
    main = b.panel("Main")
    b.robot(main)
    sensor = main.add(23, "Robot/IoT Controller 0", "1")
    drive = main.add(20, "value / 100.0", "value / 100.0", "Robot/IoT Controller 0", "3", "5")
    wait = main.add(3, "120")
    timer = main.add(15)
    stop = main.add(20, "0", "0", "Robot/IoT Controller 0", "3", "5")
    show = main.add(28, "")
    main.chain(sensor, drive, wait, timer, stop, show)
    path = b.write(tmp_path / "p.viple")
    c = ProgramController(compile_program(load_program(path)), report_period=0.25)
    readings = {"port 1": 40}
    assert c.start(0.0) == []
    for t in (0.05, 0.1, 0.15, 0.2):
        assert c.tick(t, readings, frozenset()) == []
    assert c.next_due() == 0.25 and c.steps == 0 and c.state == "0 flows"
    assert c.tick(0.25, readings, frozenset()) == [WheelPowers(0.4, 0.4)]
    assert c.state == "1 flow" and c.next_due() == pytest.approx(0.37)
    assert c.tick(0.3, readings, frozenset()) == [] and c.steps == 3
    assert c.tick(0.37, readings, frozenset()) == [WheelPowers(0.0, 0.0)]
    assert [p.text for p in c.printed] == ["120"] and c.state == "0 flows" and c.steps == 5
    assert c.next_due() == 0.5


def _run_both_ways(make, seconds, readings):
    """The run of a program with its chains of activities fused (fused.py), and with every
    activity run by its own step: everything a user sees of it, each way."""
    out = []
    for fuse in (True, False):
        c = make(fuse)
        out.append(seen(c, run(c, seconds, readings)))
    return out


def test_fused_chains_run_as_the_steps_do_errors_included(tmp_path):
    b = ProgramBuilder()
    b.var("n", "System.Int32")
    b.var("word", "System.String")
    main = b.panel("Main")
    b.robot(main)
    sensor = main.add(23, "Robot/IoT Controller 0", "1")
    touch = main.add(22, "Robot/IoT Controller 0", "2")
    # a three-way If fanning out, a Variable that cannot hold text, a Drive given text
    cond = main.add(6, "value > 50", "value > 20", "value")
    store = main.add(1, "n")
    text = main.add(3, '"fast"')
    word = main.add(1, "word")
    bad_drive = main.add(20, "value", "0.5", "Robot/IoT Controller 0", "3", "5")
    drive = main.add(20, "value / 100", "-0.25", "Robot/IoT Controller 0", "3", "5")
    wait = main.add(15)
    show = main.add(28, "")
    b.link(sensor, cond)
    b.link(cond, store, pin=0)
    b.link(cond, text, pin=0)
    b.link(text, word)
    b.link(word, store)
    b.link(word, bad_drive)
    b.link(cond, drive, pin=1)
    b.link(cond, show, pin=ELSE)
    b.link(drive, wait)
    b.link(wait, show)
    b.link(touch, show)
    # a Timer given text, and a Merge loop paced by a 0 ms Timer, both from the start
    start = main.add(3, '"soon"')
    bad_wait = main.add(15)
    main.chain(start, bad_wait)
    zero = main.add(3, "0")
    merge = main.add(5)
    again = main.add(15)
    count = main.add(2, "state.n + 1")
    b.link(zero, merge)
    main.chain(merge, again, count, store)
    # a loop waking every 10 ms for good
    ten = main.add(3, "10")
    tick = main.add(5)
    pause = main.add(15)
    same = main.add(2, "value")
    main.chain(ten, tick, pause, same, tick)
    path = b.write(tmp_path / "p.viple")

    def make(fuse: bool) -> ProgramController:
        compiled = compile_program(load_program(path))
        return ProgramController(compiled, report_period=0.25, fuse=fuse)

    def readings(t: float) -> dict[int, float]:
        return {1: (t * 37) % 90, 2: int(t * 3) % 2}

    fused, steps = _run_both_ways(make, 6.0, readings)
    assert fused == steps
    errors = steps[3]
    assert any("the Timer needs a number of milliseconds, not String" in e for e in errors)
    assert any("condition 2 gave Double, not true or false" in e for e in errors)
    assert any("the left power must be a number, not String" in e for e in errors)
    assert any("'fast' is not a number for a Int32" in e for e in errors)
    assert steps[6] > 400  # the 10 ms loop ran at every tick


@pytest.mark.parametrize("name", ["web-wall-following.viple", "right-wall.viple"])
def test_the_shipped_programs_run_the_same_fused(name):
    path = str(Path(__file__).resolve().parents[2] / "programs" / name)

    def make(fuse: bool) -> ProgramController:
        compiled = compile_program(load_program(path))
        return ProgramController(compiled, report_period=0.25, fuse=fuse)

    def readings(t: float) -> dict[int, float]:
        return {1: 10 + (t * 53) % 90, 2: int(t * 0.7) % 2}

    fused, steps = _run_both_ways(make, 60.0, readings)
    assert fused == steps and steps[6] > 500
