"""A tick's record line is the JSON of its object, character for character, however it is
put together (the recorder builds the plain ones by hand)."""

from __future__ import annotations

import io
import json
import math

from hypothesis import given, settings
from hypothesis import strategies as st

from workbench.sim.commands import MotorPower, Stop, TurnByDegrees, WheelPowers
from workbench.sim.record import Recorder, command_json


def rounded(value):
    return round(value, 4) if isinstance(value, float) else value


def tick_object(t, pose, sensors, commands, state, events, variables):
    """A tick's line as an object, as ``docs/run-record.md`` lays it out."""
    line = {
        "t": round(t, 4),
        "pose": [round(v, 4) for v in pose],
        "sensors": {str(p): rounded(v) for p, v in sensors.items()},
    }
    if commands:
        line["cmd"] = [command_json(c) for c in commands]
    if state is not None:
        line["state"] = state
    if variables:
        line["vars"] = {k: rounded(v) for k, v in variables.items()}
    if events:
        line["events"] = events
    return line


numbers = st.floats(allow_nan=True, allow_infinity=True) | st.floats(-1e4, 1e4)
readings = st.dictionaries(
    st.integers(-3, 12) | st.sampled_from(["3", 'a"b']),
    numbers | st.integers(-5, 10**20) | st.booleans() | st.none(),
    max_size=5,
)
commands = st.lists(
    st.sampled_from(
        [WheelPowers(0.5, -0.25), MotorPower("left", 0.125), TurnByDegrees(90.0), Stop()]
    ),
    max_size=2,
)
variables = st.none() | st.dictionaries(
    st.text(max_size=4), numbers | st.text(max_size=4) | st.integers(), max_size=3
)


@settings(max_examples=400, deadline=None)
@given(
    t=numbers | st.integers(0, 100),
    pose=st.tuples(numbers, numbers, numbers),
    sensors=readings,
    cmds=commands,
    state=st.none() | st.text(max_size=6),
    events=st.lists(st.sampled_from(["collision", "touch", "exit", "é"]), max_size=2),
    variables=variables,
)
def test_a_tick_line_is_the_json_of_its_object(t, pose, sensors, cmds, state, events, variables):
    out = io.StringIO()
    Recorder(out, rate=None).tick(t, pose, sensors, cmds, state, events, variables)
    line = out.getvalue().removesuffix("\n")
    assert "\n" not in line
    expected = tick_object(t, pose, sensors, cmds, state, events, variables)
    assert line == json.dumps(expected, separators=(",", ":"))


def test_the_lines_of_a_plain_run_read_back_as_written(tmp_path):
    path = tmp_path / "run.jsonl"
    recorder = Recorder(path)
    recorder.tick(0.05, (1.25, 2.5, 359.99996), {0: 0.123456, 1: 1, 3: math.inf}, [], None, [])
    recorder.tick(0.1, (1.0, -0.0, 0.0), {2: 7.0}, [Stop()], "Forward", ["touch"], {"n": 2.00004})
    recorder.close()
    lines = path.read_text().splitlines()
    first, second = (json.loads(line) for line in lines)
    assert first == {
        "t": 0.05, "pose": [1.25, 2.5, 360.0], "sensors": {"0": 0.1235, "1": 1, "3": math.inf}
    }  # fmt: skip
    assert second["cmd"] == [{"stop": True}] and second["state"] == "Forward"
    assert second["vars"] == {"n": 2.0} and second["events"] == ["touch"]
    assert '"pose":[1.0,-0.0,0.0]' in lines[1]  # a negative zero keeps its sign, as in json
