"""Sensor values a robot reports, of any JSON type, as a program's sensor activities get them."""

from __future__ import annotations

import json

from hypothesis import given, settings
from hypothesis import strategies as st

from tests.program.builder import ProgramBuilder
from workbench.program.compiled import compile_program
from workbench.program.loader import load_program_text
from workbench.program.remote import RemoteProgram
from workbench.viple.codec import CodecError, parse_report

R = "Robot/IoT Controller 0"


def remote(b: ProgramBuilder) -> RemoteProgram:
    program = RemoteProgram(compile_program(load_program_text(b.xml(), "t.viple")))
    program.start(0.0)
    return program


def send(program: RemoteProgram, t: float, line: str) -> list:
    """A report line as the client hands it over: read by the codec, then with its text."""
    return program.report(t, parse_report(line), line)


def printed(program: RemoteProgram) -> list[str]:
    return [p.text for p in program.news()[0]]


def test_a_distance_sent_as_text_compares_as_a_number():
    b = ProgramBuilder()
    main = b.panel("Main")
    b.robot(main)
    near = main.add(6, "value < 30")
    main.chain(main.add(23, R, "1"), near)
    b.link(near, main.add(28, ""))
    program = remote(b)
    send(program, 0.1, '{"sensors":[{"name":"distance","id":1,"value":"12.50"}]}')
    send(program, 0.2, '{"sensors":[{"name":"distance","id":1,"value":" 31 "}]}')
    assert printed(program) == ["12.5"]
    assert program.controller.errors == []


def test_text_reaches_the_program_as_text():
    b = ProgramBuilder()
    main = b.panel("Main")
    b.robot(main)
    said = main.add(2, '"the camera says " + value')
    main.chain(main.add(25, R, "1"), said, main.add(28, ""))
    program = remote(b)
    send(program, 0.1, '{"sensors": [{"id": 1, "name": "ai", "value": "straight"}]}')
    send(program, 0.2, '{"sensors": [{"id": 1, "name": "ai", "value": true}]}')
    send(program, 0.3, '{"sensors": [{"id": 1, "name": "ai", "value": null}]}')
    assert printed(program) == [
        "the camera says straight",
        "the camera says True",
        "the camera says ",
    ]


def test_a_touch_sensor_reads_numbers_numeric_text_and_true_and_names_anything_else():
    b = ProgramBuilder()
    main = b.panel("Main")
    b.robot(main)
    main.chain(main.add(22, R, "2"), main.add(28, ""))
    program = remote(b)
    for t, value in enumerate(['"1"', '"0"', "true", "0", '"straight"', "1"], start=1):
        send(program, t / 10, f'{{"sensors":[{{"id":2,"value":{value}}}]}}')
    assert printed(program) == ["1", "1", "1"]  # pressed at "1", true and 1: each a new press
    (error,) = program.controller.errors
    assert error.message == (
        "the touch sensor on port 2 reported 'straight': expected 0 or 1 (or true/false)"
    )


def test_a_raw_sensor_gets_every_report_as_it_arrived_even_an_empty_one():
    b = ProgramBuilder()
    main = b.panel("Main")
    b.robot(main)
    main.chain(main.add(52, R, "-1"), main.add(28, ""))
    program = remote(b)
    lines = ['{"sensors":[{"id":2,"value":555},{"id":1,"value":777}]}', '{ "sensors" : [ ] }']
    for t, line in enumerate(lines, start=1):
        send(program, t / 10, line)
    program.tick(0.35)  # a tick with no report fires nothing
    assert printed(program) == lines


any_scalar = st.one_of(st.none(), st.booleans(), st.integers(), st.floats(), st.text(max_size=10))


@settings(max_examples=300, deadline=2000)
@given(st.lists(st.tuples(st.integers(0, 3), any_scalar), max_size=4))
def test_reports_of_any_values_never_break_the_program(entries):
    """Every sensor kind on ports 0-3 reading whatever a robot sends: the codec refuses what is
    malformed, and what it lets through runs, with at most a run-time error per activity."""
    b = ProgramBuilder()
    main = b.panel("Main")
    b.robot(main)
    main.chain(main.add(52, R, "-1"), main.add(28, ""))
    for port in range(4):
        for kind in (22, 23, 25):
            sensor = main.add(kind, R, str(port))
            check = main.add(6, 'value == "straight"', "value > 1")
            main.chain(sensor, main.add(28, ""))
            b.link(sensor, check)
    program = remote(b)
    line = json.dumps({"sensors": [{"id": port, "value": value} for port, value in entries]})
    try:
        readings = parse_report(line)
    except CodecError:
        return
    program.report(0.1, readings, line)
    assert printed(program)[0] == line
    for error in program.controller.errors:
        assert error.activity in program.controller.program.activities
