"""A robot's own middleware that reports text: a student's program steers by it over
`workbench viple run FILE --connect`, and a raw sensor gets the report as it arrived."""

from __future__ import annotations

import json

import pytest

from tests.integration.fake_robot import FakeRobot, collapsed
from tests.program.builder import ProgramBuilder
from workbench.cli import main
from workbench.program.model import ELSE

#: what the robot's AI camera middleware sends, byte for byte
STRAIGHT = b'{"sensors": [{"id": 1, "name": "ai", "value": "straight"}]}\r\n'
#: the wheel powers the test program gives each camera verdict
STEERING = {"straight": (0.5, 0.5), "offset_left": (0.2, 0.5), "offset_right": (0.5, 0.2)}
CONTROLLER = "Robot/IoT Controller 0"
#: the Code Activity body course programs use to read the raw report's first value
PARSE_FIRST = (
    "public class Parse : CodeUtilities.CodeBase { public override void Execute() {"
    ' var o = JObject.Parse((string)Input); Output = o["sensors"][0]["value"]; } }'
)


def camera(verdict: str) -> bytes:
    return STRAIGHT.replace(b"straight", verdict.encode())


def steering_program(tmp_path, through_code: bool) -> str:
    """Steers by the camera's verdict: an If on the text picks the Robot Drive powers. The
    verdict comes from a sensor on port 1, or (``through_code``) from the raw report through
    the Code Activity that returns its first value, as the course's road follower reads it."""
    b = ProgramBuilder()
    main_ = b.panel("Main")
    main_.add(19, "192.0.2.7", "8124", "WiFi", "3000")
    if through_code:
        raw = main_.add(52, CONTROLLER, "-1")
        source = main_.add(44, "Parse", PARSE_FIRST)
        main_.chain(raw, source)
    else:
        source = main_.add(25, CONTROLLER, "1")
    verdicts = list(STEERING)
    decide = main_.add(6, *(f'value == "{v}"' for v in verdicts))
    b.link(source, decide)
    for pin, verdict in enumerate(verdicts):
        left, right = STEERING[verdict]
        drive = main_.add(20, str(left), str(right), CONTROLLER, "3", "5")
        b.link(decide, drive, pin=pin)
    b.link(decide, main_.add(20, "0", "0", CONTROLLER, "3", "5"), pin=ELSE)
    return b.write(tmp_path / ("road-code.viple" if through_code else "road.viple"))


class Verdicts:
    """The robot's script: each verdict is reported until the robot's wheels answer it with
    the powers the program gives it; then the next; then the robot closes."""

    def __init__(self, verdicts: list[str]) -> None:
        self.verdicts = verdicts
        self.answered = 0

    def __call__(self, robot: FakeRobot) -> bytes | None:
        powers = robot.powers()
        while self.answered < len(self.verdicts):
            wanted = STEERING[self.verdicts[self.answered]]
            if wanted not in powers[self._since :]:
                return camera(self.verdicts[self.answered])
            self._since = len(powers)
            self.answered += 1
        return None

    _since = 0


@pytest.mark.parametrize("through_code", [False, True], ids=["port sensor", "raw and code"])
def test_a_program_steers_by_a_text_sensor_of_a_real_robot(tmp_path, capsys, through_code):
    program = steering_program(tmp_path, through_code)
    verdicts = ["straight", "offset_left", "straight", "offset_right"]
    script = Verdicts(verdicts)
    with FakeRobot(script) as robot:
        code = main(["viple", "run", program, "--connect", robot.url, "--json", "--no-keyboard"])
    captured = capsys.readouterr()
    assert code == 0, captured.err
    result = json.loads(captured.out)
    assert result["ended"] == "closed" and result["rejected_reports"] == 0
    assert result["reports"] == robot.reports_sent
    assert script.answered == len(verdicts)
    # the wheels changed with the text, and only as the text said: no stop, no other powers
    assert collapsed(robot.powers()) == [STEERING[v] for v in verdicts]
    assert "error at" not in captured.err


def raw_program(tmp_path) -> str:
    """The raw report is printed as it came, and its first value (through the Code Activity)
    is printed and sent as both wheels' power, in thousandths."""
    b = ProgramBuilder()
    main_ = b.panel("Main")
    main_.add(19, "192.0.2.7", "8124", "WiFi", "3000")
    raw = main_.add(52, CONTROLLER, "-1")
    first = main_.add(44, "Parse", PARSE_FIRST)
    said = main_.add(28, "")
    drive = main_.add(20, "value / 1000.0", "value / 1000.0", CONTROLLER, "3", "5")
    main_.chain(raw, first, said, drive)
    b.link(raw, main_.add(28, ""))
    return b.write(tmp_path / "raw.viple")


@pytest.mark.parametrize(
    ("line", "shown"),
    [
        (
            b'{"sensors":[{"id":2,"value":555},{"id":1,"value":777}]}',
            '{"sensors":[{"id":2,"value":555},{"id":1,"value":777}]}',
        ),
        (  # JSON blanks inside the report reach the program; the terminal sees them escaped
            b'{"sensors":\r[{"id":2,"value":555},\t{"id":1,"value":777}]}',
            '{"sensors":\\x0d[{"id":2,"value":555},  {"id":1,"value":777}]}',
        ),
    ],
    ids=["plain", "blanks inside"],
)
def test_a_raw_sensor_gets_the_report_as_it_arrived(tmp_path, capsys, line, shown):
    def script(robot: FakeRobot) -> bytes | None:
        return None if robot.commands else line + b"\r\n"

    with FakeRobot(script) as robot:
        code = main(["viple", "run", raw_program(tmp_path), "--connect", robot.url, "--json"])
    captured = capsys.readouterr()
    assert code == 0, captured.err
    assert robot.powers()[0] == (0.555, 0.555)  # the first entry, not port 1's 777
    assert "print: 555" in captured.err
    assert f"print: {shown}\n" in captured.err  # entries in their order, as sent
    assert "\r" not in captured.err and "\t" not in captured.err
