"""VIPLE's JSON protocol: framing, commands from VIPLE, sensor reports to VIPLE."""

import json
import math
import re

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from workbench.sim.commands import (
    MotorPower,
    MoveAtPower,
    Stop,
    TurnByDegrees,
    WheelPowers,
)
from workbench.viple.codec import (
    CodecError,
    FrameError,
    FrameTooLong,
    LineSplitter,
    NotUtf8,
    WheelPorts,
    encode_command,
    encode_report,
    parse_command,
    parse_report,
    reading_number,
    split_frame,
)

WHEELS = WheelPorts(left=3, right=5)
DRIVE = (
    b'{"servos":[{"isTurn":false,"servoId":3,"servoSpeed":0.5},'
    b'{"isTurn":false,"servoId":5,"servoSpeed":0.5}]}\r\n'
)
TURN = b'{"servos":[{"isTurn":true,"servoId":-1,"servoSpeed":90}]}\r\n'
FUZZ = settings(max_examples=500, deadline=None)


def servos(*entries: dict) -> str:
    return json.dumps({"servos": list(entries)})


def rejection(line: str, line_no: int | None = None) -> str:
    with pytest.raises(CodecError) as info:
        parse_command(line, WHEELS, line_no)
    return str(info.value)


# --- framing ---------------------------------------------------------------------------------


def test_a_viple_drive_line_arrives_as_one_command():
    (line,) = LineSplitter().feed(DRIVE)
    assert parse_command(line, WHEELS) == [WheelPowers(0.5, 0.5)]


def test_several_lines_in_one_read_are_all_returned_in_order():
    lines = LineSplitter().feed(DRIVE + TURN + b'{"servos":[{"servoSpeed":0}]}\n')
    assert [parse_command(line, WHEELS) for line in lines] == [
        [WheelPowers(0.5, 0.5)],
        [TurnByDegrees(90)],
        [MoveAtPower(0)],
    ]


def test_a_line_split_across_reads_is_joined():
    splitter = LineSplitter()
    assert splitter.feed(DRIVE[:20]) == []
    assert splitter.feed(DRIVE[20:-1]) == []
    assert splitter.feed(DRIVE[-1:] + TURN[:5]) == [DRIVE[:-2].decode()]
    assert splitter.feed(TURN[5:]) == [TURN[:-2].decode()]


def test_every_byte_in_its_own_read_still_gives_the_lines():
    splitter = LineSplitter()
    lines = [line for byte in DRIVE + TURN for line in splitter.feed(bytes([byte]))]
    assert lines == [DRIVE[:-2].decode(), TURN[:-2].decode()]


def test_bare_newlines_and_blank_lines_are_accepted():
    data = b'\r\n\n  \r\n{"servos":[{"servoSpeed":1}]}\n\n'
    assert LineSplitter().feed(data) == ['{"servos":[{"servoSpeed":1}]}']


def test_a_line_that_is_not_utf8_is_dropped_and_its_neighbours_kept():
    splitter = LineSplitter()
    with pytest.raises(NotUtf8) as info:
        splitter.feed(DRIVE + b'{"servos":\xff}\r\n' + TURN)
    assert "not UTF-8 text at byte 11 (0xff" in str(info.value)
    assert info.value.lines == [DRIVE[:-2].decode(), TURN[:-2].decode()]
    assert splitter.feed(DRIVE) == [DRIVE[:-2].decode()]


def test_non_ascii_text_split_inside_a_character_is_accepted():
    data = '{"servos":[{"servoSpeed":1,"note":"vitesse é"}]}\n'.encode()
    cut = data.index(b"\xc3") + 1
    splitter = LineSplitter()
    assert splitter.feed(data[:cut]) == []
    (line,) = splitter.feed(data[cut:])
    assert parse_command(line, WHEELS) == [MoveAtPower(1)]


def test_a_line_at_the_limit_is_accepted_with_its_crlf():
    line = b"{" + b" " * 8 + b"}"
    splitter = LineSplitter(max_bytes=10)
    assert splitter.feed(line + b"\r") == []
    assert splitter.feed(b"\n") == ["{        }"]


def test_an_overlong_complete_line_is_reported_with_its_size_and_the_limit():
    splitter = LineSplitter(max_bytes=100)
    with pytest.raises(FrameTooLong) as info:
        splitter.feed(TURN + b"x" * 150 + b"\r\n" + TURN)
    assert "line of 150 bytes is longer than the limit of 100 bytes" in str(info.value)
    assert info.value.lines == [TURN[:-2].decode()] * 2


def test_an_overlong_unfinished_line_is_dropped_up_to_its_end_without_buffering_it():
    splitter = LineSplitter(max_bytes=100)
    splitter.feed(b"x" * 60)
    with pytest.raises(FrameTooLong) as info:
        splitter.feed(b"x" * 60)
    assert "unfinished line of 120 bytes" in str(info.value)
    assert "limit of 100 bytes" in str(info.value)
    assert splitter.pending_bytes == 0
    assert splitter.feed(b"x" * 10_000) == []
    assert splitter.pending_bytes == 0
    assert splitter.feed(b"xx\r\n" + TURN) == [TURN[:-2].decode()]


def test_problems_of_one_read_are_reported_together():
    splitter = LineSplitter(max_bytes=100)
    with pytest.raises(FrameError) as info:
        splitter.feed(b"x" * 101 + b"\n\xc3\n" + TURN)
    assert len(info.value.reasons) == 2
    assert info.value.lines == [TURN[:-2].decode()]


def test_a_websocket_frame_holds_one_object_or_several_on_lines():
    assert split_frame(DRIVE[:-2].decode()) == [DRIVE[:-2].decode()]
    assert split_frame((DRIVE + b"\r\n" + TURN).decode()) == [
        DRIVE[:-2].decode(),
        TURN[:-2].decode(),
    ]
    assert split_frame(" \r\n") == []


# --- receiver rules --------------------------------------------------------------------------


def test_drive_entries_are_matched_to_wheels_by_port_not_by_order():
    line = servos({"servoId": 5, "servoSpeed": -0.2}, {"servoId": 3, "servoSpeed": 0.2})
    assert parse_command(line, WHEELS) == [WheelPowers(left=0.2, right=-0.2)]


def test_drive_entries_with_unknown_ports_are_taken_in_array_order():
    line = servos({"servoId": 1, "servoSpeed": 0.2}, {"servoId": 2, "servoSpeed": -0.2})
    assert parse_command(line, WHEELS) == [WheelPowers(left=0.2, right=-0.2)]


def test_a_motor_entry_on_the_right_port_drives_only_the_right_wheel():
    line = servos({"isTurn": False, "servoId": 5, "servoSpeed": 0.7})
    assert parse_command(line, WHEELS) == [MotorPower("right", 0.7)]


def test_a_single_motor_entry_on_an_unknown_port_drives_the_left_wheel():
    line = servos({"isTurn": False, "servoId": 8, "servoSpeed": 0.7})
    assert parse_command(line, WHEELS) == [MotorPower("left", 0.7)]


def test_entries_on_other_ports_are_ignored_when_one_matches_a_wheel():
    line = servos({"servoId": 8, "servoSpeed": 1}, {"servoId": 3, "servoSpeed": 0.4})
    assert parse_command(line, WHEELS) == [MotorPower("left", 0.4)]


@pytest.mark.parametrize(
    "entry",
    [
        {"isTurn": False, "servoId": -1, "servoSpeed": 0.6},
        {"servoId": -1, "servoSpeed": 0.6},
        {"servoSpeed": 0.6},
        {"servoId": None, "isTurn": None, "servoSpeed": 0.6},
        {"servoId": "-1", "isTurn": "false", "servoSpeed": "0.6"},
    ],
)
def test_robot_plus_move_at_power(entry):
    assert parse_command(servos(entry), WHEELS) == [MoveAtPower(0.6)]


@pytest.mark.parametrize("flag", [True, "true", "True", " TRUE "])
def test_robot_plus_turn_by_degree_keeps_the_degrees(flag):
    line = servos({"isTurn": flag, "servoId": -1, "servoSpeed": -135})
    assert parse_command(line, WHEELS) == [TurnByDegrees(-135)]


@pytest.mark.parametrize(
    ("speed", "power"), [(2.5, 1.0), (-3, -1.0), ("0.5", 0.5), (" -1 ", -1.0), ("+.25", 0.25)]
)
def test_powers_are_read_from_numbers_or_numeric_strings_and_clamped(speed, power):
    line = servos({"servoId": 3, "servoSpeed": speed}, {"servoId": 5, "servoSpeed": speed})
    assert parse_command(line, WHEELS) == [WheelPowers(power, power)]


def test_port_numbers_may_be_strings_or_whole_floats():
    line = servos({"servoId": "3", "servoSpeed": 1}, {"servoId": 5.0, "servoSpeed": -1})
    assert parse_command(line, WHEELS) == [WheelPowers(1, -1)]


def test_unknown_keys_are_ignored():
    line = json.dumps(
        {
            "robot": "sim",
            "servos": [{"servoId": 3, "servoSpeed": 1, "extra": [1, {"x": None}]}],
        }
    )
    assert parse_command(line, WHEELS) == [MotorPower("left", 1)]


def test_robot_plus_and_wheel_entries_in_one_message_apply_in_array_order():
    line = servos(
        {"servoId": -1, "isTurn": True, "servoSpeed": 90},
        {"servoId": 3, "servoSpeed": 0.3},
        {"servoId": -1, "servoSpeed": 0},
        {"servoId": 5, "servoSpeed": 0.4},
    )
    assert parse_command(line, WHEELS) == [
        TurnByDegrees(90),
        WheelPowers(0.3, 0.4),
        MoveAtPower(0),
    ]


def test_a_utf8_byte_order_mark_before_the_object_is_ignored():
    assert parse_command("\ufeff" + TURN[:-2].decode(), WHEELS) == [TurnByDegrees(90)]


# --- rejections ------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("line", "message"),
    [
        (
            servos({"servoSpeed": "fast"}),
            'line 3: servos[0].servoSpeed "fast" is not a number; expected a number like 0.5, or a'
            " string holding one",
        ),
        ("[1, 2]", 'line 3: expected a JSON object with "servos", got a list'),
        ('"servos"', 'line 3: expected a JSON object with "servos", got a string'),
        (
            '{"sensors": []}',
            'line 3: expected a JSON object with "servos", got an object with keys "sensors"',
        ),
        ("{}", 'line 3: expected a JSON object with "servos", got an empty object'),
        (
            '{"servos": [{"servoId": 3 "servoSpeed": 1}]}',
            "line 3: not JSON: Expecting ',' delimiter at column 27",
        ),
        ("", "line 3: not JSON: the line is empty"),
        ('{"servos": []}', "line 3: servos is empty; expected at least one entry"),
        (
            '{"servos": {"servoSpeed": 1}}',
            "line 3: servos is an object; expected a list of entries",
        ),
        (
            '{"servos": [0.5]}',
            'line 3: servos[0] is a number; expected an object like {"servoId":3,"servoSpeed":0.5}',
        ),
        (
            servos({"servoId": 3}),
            "line 3: servos[0].servoSpeed is missing; expected a number like 0.5, or a string"
            " holding one",
        ),
        (
            servos({"servoSpeed": None}),
            "line 3: servos[0].servoSpeed is null; expected a number like 0.5, or a string"
            " holding one",
        ),
        (
            servos({"servoSpeed": True}),
            "line 3: servos[0].servoSpeed is true/false; expected a number like 0.5, or a string"
            " holding one",
        ),
        (
            servos({"servoSpeed": [1]}),
            "line 3: servos[0].servoSpeed is a list; expected a number like 0.5, or a string"
            " holding one",
        ),
        (
            servos({"servoSpeed": "NaN"}),
            'line 3: servos[0].servoSpeed "NaN" is not a number; expected a number like 0.5, or a'
            " string holding one",
        ),
        (
            servos({"servoSpeed": "1e999"}),
            'line 3: servos[0].servoSpeed "1e999" is out of range; expected a finite number',
        ),
        (
            '{"servos": [{"servoSpeed": 1e999}]}',
            "line 3: servos[0].servoSpeed 1e999 is out of range; expected a finite number",
        ),
        ('{"servos": [{"servoSpeed": NaN}]}', "line 3: not JSON: NaN is not a JSON value"),
        (
            '{"servos": [{"servoSpeed": -Infinity}]}',
            "line 3: not JSON: -Infinity is not a JSON value",
        ),
        (
            servos({"isTurn": "yes", "servoSpeed": 1}),
            'line 3: servos[0].isTurn "yes" is not true or false; expected true, false, "true" or'
            ' "false"',
        ),
        (
            servos({"isTurn": 1, "servoSpeed": 1}),
            "line 3: servos[0].isTurn 1 is not true or false; expected true, false,"
            ' "true" or "false"',
        ),
        (
            servos({"servoId": 2.5, "servoSpeed": 1}),
            "line 3: servos[0].servoId 2.5 is not a whole number; expected a port number like 3, or"
            " -1 for the Robot+ services",
        ),
        (
            servos({"servoId": -2, "servoSpeed": 1}),
            "line 3: servos[0].servoId -2 is not a port; expected a port number like 3, or -1 for"
            " the Robot+ services",
        ),
        (
            servos({"servoId": 3, "servoSpeed": 1}, {"servoId": 3, "servoSpeed": 0}),
            "line 3: servos[1].servoId 3 is the left wheel again; expected one entry per wheel",
        ),
        (
            servos(*({"servoId": n, "servoSpeed": 1} for n in (1, 2, 4))),
            "line 3: servos has 3 wheel entries (servoId 1, 2, 4) and none matches the wheel"
            " ports; expected the left (3) and right (5) wheel ports",
        ),
        ("[" * 100_000, "line 3: not JSON: nested too deeply to read"),
    ],
)
def test_bad_lines_are_rejected_with_a_specific_reason(line, message):
    assert rejection(line, line_no=3) == message


def test_the_reason_has_no_line_prefix_without_a_line_number():
    assert rejection("[]") == 'expected a JSON object with "servos", got a list'


def test_long_values_are_shortened_in_the_reason():
    message = rejection(servos({"servoSpeed": "x" * 500}))
    assert len(message) < 140 and "x" * 50 not in message and "…" in message


def test_a_huge_integer_is_out_of_range_not_a_crash():
    message = rejection('{"servos":[{"servoSpeed":' + "9" * 5000 + "}]}")
    assert message.startswith("servos[0].servoSpeed 9999") and "is out of range" in message


def test_wheel_ports_must_differ():
    with pytest.raises(ValueError, match="different ports"):
        WheelPorts(3, 3)


# --- sensor reports --------------------------------------------------------------------------


def test_a_report_matches_the_protocol_example_byte_for_byte():
    report = encode_report({2: 0, 1: 1.734}, {2: "touch", 1: "distance"})
    assert report == (
        '{"sensors":[{"name":"distance","id":1,"value":1.734},{"name":"touch","id":2,"value":0}]}'
    )


@pytest.mark.parametrize(
    ("value", "text"),
    [
        (1000.0, "1000"),
        (0.1234567, "0.123"),
        (0.00001, "0"),
        (-0.0001, "0"),
        (1e20, "100000000000000000000"),
        (25, "25"),
    ],
)
def test_distances_are_plain_numbers_with_at_most_three_decimals(value, text):
    assert encode_report({4: value}, {4: "distance"}) == (
        f'{{"sensors":[{{"name":"distance","id":4,"value":{text}}}]}}'
    )


@pytest.mark.parametrize(("pressed", "text"), [(True, "1"), (1.0, "1"), (False, "0"), (0, "0")])
def test_touch_is_sent_as_integer_zero_or_one(pressed, text):
    assert encode_report({2: pressed}, {2: "touch"}).endswith(f'"value":{text}}}]}}')


def test_a_report_without_sensors_is_an_empty_list():
    assert encode_report({}, {}) == '{"sensors":[]}'


@pytest.mark.parametrize(
    ("readings", "kinds", "message"),
    [
        ({1: float("nan")}, {1: "distance"}, "distance sensor on port 1: cannot send nan"),
        ({1: float("inf")}, {1: "distance"}, "distance sensor on port 1: cannot send inf"),
        ({}, {1: "distance"}, "no reading for the sensor on port 1"),
        ({1: 1.0, 7: 0}, {1: "distance"}, "reading for port 7"),
        ({1: 1.0}, {1: "radar"}, "unknown sensor kind 'radar'"),
    ],
)
def test_a_report_that_cannot_be_sent_is_refused(readings, kinds, message):
    with pytest.raises(ValueError, match=message):
        encode_report(readings, kinds)


def test_a_report_is_read_back_with_its_values_as_sent():
    line = (
        '{"sensors":[{"name":"distance","id":"1","value":"1.5"},'
        '{"name":"touch","id":2,"value":1},{"name":"distance","id":3,"value":1000,"x":0}]}'
    )
    readings = parse_report(line)
    assert readings == {1: "1.5", 2: 1.0, 3: 1000.0}
    # a reader that needs a number (an FSM) reads the Unity simulator's "1.5" as 1.5
    assert [reading_number(value, port) for port, value in readings.items()] == [1.5, 1, 1000]


def test_a_robot_reports_text_and_every_other_json_scalar():
    line = '{"sensors": [{"id": 1, "name": "ai", "value": "straight"}]}'
    assert parse_report(line) == {1: "straight"}
    line = '{"sensors":[{"id":4,"value":true},{"id":2,"value":null},{"id":3,"value":"été"}]}'
    assert parse_report(line) == {4: True, 2: None, 3: "été"}


def test_readings_keep_the_order_of_the_report():
    assert list(parse_report('{"sensors":[{"id":2,"value":555},{"id":1,"value":777}]}')) == [2, 1]


@pytest.mark.parametrize(
    ("value", "message"),
    [
        (
            '"straight"',
            'the reading of port 1 "straight" is not a number; expected a number, or text '
            "holding one",
        ),
        ("true", "the reading of port 1 is true/false; expected a number, or text holding one"),
        ("null", "the reading of port 1 is null; expected a number, or text holding one"),
    ],
)
def test_a_reader_that_needs_a_number_refuses_other_values_by_port(value, message):
    (reading,) = parse_report('{"sensors":[{"id":1,"value":' + value + "}]}").values()
    with pytest.raises(CodecError) as info:
        reading_number(reading, 1)
    assert str(info.value) == message


@pytest.mark.parametrize(
    ("line", "message"),
    [
        (
            '{"servos":[]}',
            'line 9: expected a JSON object with "sensors", got an object with keys "servos"',
        ),
        (
            '{"sensors":[{"id":1}]}',
            'line 9: sensors[0].value is missing; expected a number like 1.5, text like "straight",'
            " true, false or null",
        ),
        (
            '{"sensors":[{"value":1}]}',
            "line 9: sensors[0].id is missing; expected a port number like 1",
        ),
        (
            '{"sensors":[{"id":1,"value":[1.5]}]}',
            'line 9: sensors[0].value is a list; expected a number like 1.5, text like "straight",'
            " true, false or null",
        ),
        (
            '{"sensors":[{"id":1,"value":{"ai":"straight"}}]}',
            "line 9: sensors[0].value is an object; expected a number like 1.5, text like "
            '"straight", true, false or null',
        ),
        (
            '{"sensors":[{"id":1,"value":1e400}]}',
            "line 9: sensors[0].value 1e400 is out of range; expected a finite number",
        ),
        (
            '{"sensors":[{"id":1,"value":"\\u001b[2Jstraight"}]}',
            'line 9: sensors[0].value "\\u001b[2Jstraight" holds a control character (U+001B) at'
            " character 1; expected text without control characters",
        ),
        (
            '{"sensors":[{"id":1,"value":"left\\udc00"}]}',
            'line 9: sensors[0].value "left\\udc00" holds a lone surrogate (U+DC00) at character'
            " 5; expected text without control characters",
        ),
        (
            '{"sensors":[{"id":1,"value":1},{"id":1,"value":2}]}',
            "line 9: sensors[1].id 1 is the port of sensors[0] too; expected one entry per port",
        ),
        (
            '{"sensors":["distance"]}',
            "line 9: sensors[0] is a string; expected an object like"
            ' {"name":"distance","id":1,"value":1.5}',
        ),
        (
            '{"sensors":[{"id":1,"value":Infinity}]}',
            "line 9: not JSON: Infinity is not a JSON value",
        ),
    ],
)
def test_bad_reports_are_rejected_with_a_specific_reason(line, message):
    with pytest.raises(CodecError) as info:
        parse_report(line, line_no=9)
    assert str(info.value) == message


# --- commands as VIPLE sends them ------------------------------------------------------------


@pytest.mark.parametrize(
    ("command", "line"),
    [
        (WheelPowers(0.5, 0.5), DRIVE[:-2].decode()),
        (TurnByDegrees(90), TURN[:-2].decode()),
        (
            WheelPowers(0.2, -0.2),
            '{"servos":[{"isTurn":false,"servoId":3,"servoSpeed":0.2},'
            '{"isTurn":false,"servoId":5,"servoSpeed":-0.2}]}',
        ),
        (MotorPower("right", 1), '{"servos":[{"isTurn":false,"servoId":5,"servoSpeed":1}]}'),
        (MoveAtPower(-0.75), '{"servos":[{"isTurn":false,"servoId":-1,"servoSpeed":-0.75}]}'),
        (
            Stop(),
            '{"servos":[{"isTurn":false,"servoId":3,"servoSpeed":0},'
            '{"isTurn":false,"servoId":5,"servoSpeed":0}]}',
        ),
    ],
)
def test_commands_are_encoded_exactly_as_viple_sends_them(command, line):
    assert encode_command(command, WHEELS) == line


def test_stop_reads_back_as_both_wheels_at_zero():
    assert parse_command(encode_command(Stop(), WHEELS), WHEELS) == [WheelPowers(0, 0)]


powers = st.floats(-1, 1).map(lambda p: round(p, 6))
commands = st.one_of(
    st.builds(WheelPowers, powers, powers),
    st.builds(MotorPower, st.sampled_from(["left", "right"]), powers),
    st.builds(MoveAtPower, powers),
    st.builds(TurnByDegrees, st.floats(-720, 720).map(lambda d: round(d, 6))),
)
ports = st.integers(0, 99)


@FUZZ
@given(commands, ports, ports)
def test_an_encoded_command_reads_back_as_the_same_command(command, left, right):
    if left == right:
        right = (left + 1) % 100
    wheels = WheelPorts(left, right)
    assert parse_command(encode_command(command, wheels), wheels) == [command]


@FUZZ
@given(
    st.dictionaries(
        ports,
        st.one_of(
            st.tuples(st.just("touch"), st.booleans()),
            st.tuples(st.just("distance"), st.floats(0, 1000).map(lambda v: round(v, 3))),
        ),
    )
)
def test_an_encoded_report_reads_back_as_the_same_readings(sensors):
    readings = {port: value for port, (_, value) in sensors.items()}
    kinds = {port: kind for port, (kind, _) in sensors.items()}
    report = encode_report(readings, kinds)
    values = re.findall(r'"value":([^}]*)}', report)
    assert all(re.fullmatch(r"-?[0-9]+(\.[0-9]{1,3})?", text) for text in values)
    assert parse_report(report) == {port: float(value) for port, value in readings.items()}


# --- anything at all -------------------------------------------------------------------------

json_values = st.recursive(
    st.none()
    | st.booleans()
    | st.integers()
    | st.floats()
    | st.text(max_size=8)
    | st.sampled_from(["servos", "sensors", "servoId", "servoSpeed", "isTurn", "-1", "0.5"]),
    lambda inner: (
        st.lists(inner, max_size=4)
        | st.dictionaries(
            st.sampled_from(["servos", "servoId", "servoSpeed", "isTurn", "id", "value", "x"]),
            inner,
            max_size=4,
        )
    ),
    max_leaves=20,
)


def read_everything(line: str) -> None:
    for parse in (lambda: parse_command(line, WHEELS, 1), lambda: parse_report(line, 1)):
        try:
            parse()
        except CodecError as err:
            assert str(err).startswith("line 1: ")


@FUZZ
@given(st.binary(max_size=300), st.lists(st.integers(1, 50), max_size=10))
def test_arbitrary_bytes_only_ever_give_codec_errors(data, cuts):
    splitter = LineSplitter(max_bytes=64)
    start = 0
    for size in [*cuts, len(data)]:
        try:
            lines = splitter.feed(data[start : start + size])
        except FrameError as err:
            lines = err.lines
        for line in lines:
            read_everything(line)
        start += size
    assert splitter.pending_bytes <= 65


@FUZZ
@given(json_values)
def test_arbitrary_json_only_ever_gives_codec_errors(value):
    read_everything(json.dumps(value))
    read_everything(json.dumps({"servos": value}))
    read_everything(json.dumps({"servos": [value]}))
    read_everything(json.dumps({"sensors": [value]}))


@FUZZ
@given(st.text(max_size=200))
def test_arbitrary_text_only_ever_gives_codec_errors(text):
    read_everything(text)
    for part in split_frame(text):
        read_everything(part)


# --- the whole parse surface ------------------------------------------------------------------


@pytest.mark.parametrize(
    ("speed", "shown"),
    [
        ("\u001e0.5", r'"\u001e0.5"'),
        ("\u001c1", r'"\u001c1"'),
        ("0.5\u0000", r'"0.5\u0000"'),
        ("\u20000.5", r'"\u20000.5"'),
        ("\u0660", '"\u0660"'),
        ("1_000", '"1_000"'),
        ("0x10", '"0x10"'),
        ("Infinity", '"Infinity"'),
        ("-inf", '"-inf"'),
        ("nan", '"nan"'),
        ("", '""'),
        ("\ud800", r'"\ud800"'),
    ],
)
def test_a_number_string_with_anything_but_a_plain_number_is_rejected(speed, shown):
    line = servos({"servoId": 3, "servoSpeed": speed})
    assert rejection(line, 1) == (
        f"line 1: servos[0].servoSpeed {shown} is not a number; expected a number like 0.5, "
        "or a string holding one"
    )


@pytest.mark.parametrize("speed", ["0.5", " 0.5", "0.5\t", "\r\n0.5 ", "+0.5", "5e-1", ".5"])
def test_a_number_string_may_have_json_blanks_around_it(speed):
    line = servos({"servoId": 3, "servoSpeed": speed})
    assert parse_command(line, WHEELS) == [MotorPower("left", 0.5)]


@pytest.mark.parametrize(
    "speed", ["1e999", "-1e999", "9" * 400, "1" + "0" * 309 + ".5", "0." + "0" * 400 + "1e999"]
)
def test_a_number_string_too_large_for_a_float_is_out_of_range(speed):
    message = rejection(servos({"servoId": 3, "servoSpeed": speed}))
    assert message.startswith("servos[0].servoSpeed ")
    assert message.endswith("is out of range; expected a finite number")


def test_the_wheel_port_of_a_number_string_is_named_when_it_is_not_a_number():
    message = rejection(servos({"servoId": "three", "servoSpeed": 1}))
    assert message == (
        'servos[0].servoId "three" is not a number; expected a port number like 3, or -1 for the '
        "Robot+ services"
    )


def test_a_lone_surrogate_anywhere_is_read_without_crashing_and_shown_escaped():
    assert rejection('{"servos":[{"servoId":3,"servoSpeed":"\\ud800"}]}').startswith(
        'servos[0].servoSpeed "\\ud800" is not a number'
    )
    assert rejection('{"\\udfff":1}') == (
        'expected a JSON object with "servos", got an object with keys "\\udfff"'
    )
    line = '{"servos":[{"servoId":3,"servoSpeed":1,"\\ud800":"\\udc00"}]}'
    assert parse_command(line, WHEELS) == [MotorPower("left", 1)]


@pytest.mark.parametrize(
    ("line", "message"),
    [
        (
            '{"servos":[{"servoId":3,"servoSpeed":1,"servoSpeed":0}]}',
            'servos[0] has the key "servoSpeed" more than once; expected each key once',
        ),
        (
            '{"servos":[{"servoSpeed":1}],"servos":[{"servoSpeed":0}]}',
            'the message has the key "servos" more than once; expected each key once',
        ),
        (
            '{"servos":[{"servoSpeed":1},{"isTurn":true,"servoSpeed":9,"isTurn":false}]}',
            'servos[1] has the key "isTurn" more than once; expected each key once',
        ),
    ],
)
def test_a_key_given_twice_is_rejected_instead_of_keeping_one_of_its_values(line, message):
    assert rejection(line) == message


def test_a_repeated_key_in_a_sensor_entry_is_rejected():
    with pytest.raises(CodecError, match=r"sensors\[0\] has the key \"value\" more than once"):
        parse_report('{"sensors":[{"id":1,"value":1,"value":2}]}')


@pytest.mark.parametrize("opening", ["[", '{"a":', '{"servos":['])
def test_deep_nesting_within_the_line_limit_is_rejected_not_a_crash(opening):
    line = opening * (65536 // len(opening))
    assert rejection(line).startswith("not JSON: ")


@pytest.mark.parametrize(
    ("servo_id", "message"),
    [
        (True, "servos[0].servoId is true/false; expected a port number like 3"),
        ({}, "servos[0].servoId is an object; expected a port number like 3"),
        ("1e999", 'servos[0].servoId "1e999" is out of range; expected a finite number'),
        ("-2", "servos[0].servoId -2 is not a port; expected a port number like 3"),
        (" 2.5 ", 'servos[0].servoId " 2.5 " is not a whole number; expected a port number'),
    ],
)
def test_a_bad_servo_id_names_its_place_and_what_is_expected(servo_id, message):
    assert rejection(servos({"servoId": servo_id, "servoSpeed": 1})).startswith(message)


def test_the_reported_control_character_line_is_one_rejection_with_its_place():
    line = '{"servos":[{"servoId":3,"servoSpeed":"\\u001e0.5"}]}'
    assert rejection(line, 7) == (
        'line 7: servos[0].servoSpeed "\\u001e0.5" is not a number; expected a number like 0.5, '
        "or a string holding one"
    )


# --- near-valid messages, fuzzed ---------------------------------------------------------------


class _Raw(str):
    """A JSON value written out as is (a number literal json.dumps could not write)."""


number_texts = st.one_of(
    st.from_regex(r"[+-]?[0-9]{1,3}(\.[0-9]{0,3})?([eE][+-]?[0-9]{1,4})?", fullmatch=True),
    st.sampled_from(["NaN", "Infinity", "-Infinity", "nan", "inf", "1e999", "9" * 400, "0x1"]),
)
odd_characters = st.sampled_from(
    ["\u001e", "\u001c", "\u0000", "\u2000", "\u00a0", "\ufeff", "\ud800", "\u0660", " ", "\t"]
)
around = st.just("") | odd_characters | st.text(max_size=2)
number_strings = st.builds(lambda *parts: "".join(parts), around, number_texts, around)
field_values = st.one_of(
    number_strings,
    number_strings,
    number_texts.map(lambda text: _Raw(text)),
    json_values,
    st.sampled_from([True, False, None, "true", " FALSE ", -1, 3, 5, "-1", "3", 5.0]),
)


def json_text(value) -> str:
    """JSON for ``value``; a list of pairs is an object whose keys may repeat."""
    if isinstance(value, _Raw):
        return str(value)
    if isinstance(value, tuple):
        return "{" + ",".join(f"{json.dumps(k)}:{json_text(v)}" for k, v in value) + "}"
    if isinstance(value, list):
        return "[" + ",".join(json_text(item) for item in value) + "]"
    return json.dumps(value)


def entries(keys: list[str]):
    pair = st.tuples(st.sampled_from(keys), field_values)
    return st.lists(pair, min_size=1, max_size=5).map(tuple)


def check_only_codec_errors(line: str) -> None:
    for parse in (lambda: parse_command(line, WHEELS, 1), lambda: parse_report(line, 1)):
        try:
            parse()
        except CodecError as err:
            reason = str(err)
            assert reason.startswith("line 1: ")
            assert reason.isprintable(), reason
            reason.encode("utf-8")


@FUZZ
@given(st.lists(entries(["servoId", "servoSpeed", "isTurn", "x"]), min_size=1, max_size=4))
def test_near_valid_commands_give_commands_or_a_codec_error(servo_entries):
    line = json_text((("servos", list(servo_entries)),))
    check_only_codec_errors(line)
    try:
        commands = parse_command(line, WHEELS)
    except CodecError:
        return
    assert commands and all(
        isinstance(c, WheelPowers | MotorPower | MoveAtPower | TurnByDegrees) for c in commands
    )
    assert all(
        math.isfinite(value)
        for c in commands
        for value in vars(c).values()
        if isinstance(value, float)
    )


@FUZZ
@given(st.lists(entries(["name", "id", "value", "x"]), min_size=1, max_size=4))
def test_near_valid_reports_give_readings_or_a_codec_error(sensor_entries):
    line = json_text((("sensors", list(sensor_entries)),))
    check_only_codec_errors(line)


@FUZZ
@given(st.binary(max_size=400))
def test_arbitrary_bytes_as_a_line_give_only_codec_errors(data):
    check_only_codec_errors(data.decode("utf-8", errors="replace"))
    check_only_codec_errors(data.decode("latin-1"))


def test_a_reason_stays_short_however_many_entries_the_line_has():
    line = servos(*({"servoId": n, "servoSpeed": 1} for n in range(6, 2000)))
    message = rejection(line)
    assert message.startswith("servos has 1994 wheel entries (servoId 6, 7, 8, 9, 10, …)")
    assert len(message) < 200


# --- sensor values of any JSON type -----------------------------------------------------------

sensor_values = st.one_of(
    st.none(),
    st.booleans(),
    st.integers(),
    st.integers(min_value=10**308, max_value=10**400),
    st.floats(),
    st.text(max_size=12),
    st.lists(st.integers(), max_size=2),
    st.dictionaries(st.text(max_size=3), st.integers(), max_size=2),
)


def expected_reading(value):
    """What a report carrying ``value`` gives: ("ok", reading) or ("refused", the reason's
    start), worked out apart from the codec."""
    path = "line 1: sensors[0].value"
    if isinstance(value, float) and not math.isfinite(value):
        return "refused", "line 1: not JSON: "
    if isinstance(value, list):
        return "refused", f"{path} is a list; expected"
    if isinstance(value, dict):
        return "refused", f"{path} is an object; expected"
    is_int = isinstance(value, int) and not isinstance(value, bool)
    if is_int and not math.isfinite(float(str(value))):
        return "refused", f"{path} {str(value)[:39]}"
    if isinstance(value, str):
        codes = [ord(c) for c in value]
        if any(c < 0x20 or 0x7F <= c <= 0x9F or 0xD800 <= c < 0xE000 for c in codes):
            return "refused", f"{path} "
        return "ok", value
    if isinstance(value, bool) or value is None:
        return "ok", value
    return "ok", float(value)


@FUZZ
@given(sensor_values, st.integers(0, 99), st.sampled_from(["distance", "ai", "", "touch"]))
def test_a_sensor_value_of_any_json_type_is_read_as_sent_or_refused_naming_it(value, port, name):
    line = json.dumps({"sensors": [{"id": port, "name": name, "value": value}]})
    outcome, expected = expected_reading(value)
    if outcome == "ok":
        assert parse_report(line, 1) == {port: expected}
        return
    with pytest.raises(CodecError) as info:
        parse_report(line, 1)
    assert str(info.value).startswith(expected)
    if expected.startswith("line 1: sensors[0].value"):
        assert "expected" in str(info.value)


@FUZZ
@given(st.lists(st.tuples(st.integers(0, 9), sensor_values), max_size=5))
def test_a_report_of_any_values_gives_readings_in_its_order_or_one_refusal(entries):
    line = json.dumps({"sensors": [{"id": port, "value": value} for port, value in entries]})
    try:
        readings = parse_report(line, 1)
    except CodecError as err:
        assert re.match(r"line 1: (not JSON: |sensors\[\d\]\.(value|id) )", str(err)), str(err)
        return
    assert list(readings) == [port for port, _ in entries]
    for port, value in readings.items():
        try:
            number = reading_number(value, port)
        except CodecError as err:
            assert str(err).startswith(f"the reading of port {port} ")
        else:
            assert math.isfinite(number)
