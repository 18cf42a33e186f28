"""What `workbench viple show` and `viple run` print, read as a person reads it: keys by name,
conditions and code whole, nothing dropped without saying what, counts in the right number."""

from __future__ import annotations

import re
from pathlib import Path

from tests.program.builder import ProgramBuilder
from workbench.cli import main
from workbench.cli.viple_program import printed_summary
from workbench.program.interp import MAX_PRINTED, ProgramController
from workbench.program.keys import parse_key_script
from workbench.program.pilot import load_compiled
from workbench.program.show import one_line

WEB_MAZE = str(Path(__file__).resolve().parents[2] / "mazes" / "web.txt")

CONDITION = (
    'state.Status == "Forward" AND value < state.BaseDistance - 5 AND '
    'state.LeftDistance > state.BaseDistance + 40 OR state.Status == "TurningRightSlowly"'
)
CODE = """\
using Newtonsoft.Json.Linq;
public class Reader : CodeUtilities.CodeBase {
\tpublic override void Execute() {
\t\tvar o = JObject.Parse((string)Input);
\t\tOutput = o["sensors"][0]["value"];
\t}
}"""


def show(tmp_path, capsys, build) -> list[str]:
    b = ProgramBuilder()
    b.var("Status", "System.String")
    b.var("BaseDistance")
    b.var("LeftDistance")
    panel = b.panel("Main")
    b.robot(panel)
    build(panel)
    path = b.write(tmp_path / "p.viple")
    assert main(["viple", "show", path]) == 0
    out = capsys.readouterr().out.splitlines()
    assert max(len(line) for line in out) <= 80
    return out


def test_key_press_events_show_key_names(tmp_path, capsys):
    def build(panel):
        panel.add(13, "0")
        panel.add(13, "22")
        panel.add(13, "36")
        panel.add(13, "59")
        panel.add(13, "0", "3")

    out = show(tmp_path, capsys, build)
    keys = [line.split(": ", 1)[1] for line in out if "Key Press Event" in line]
    assert keys == ["a", "w", "up", "space", "a+d"]


def test_long_conditions_wrap_under_their_activity_and_lose_nothing(tmp_path, capsys):
    def build(panel):
        decide = panel.add(6, CONDITION, "value > 0")
        panel.chain(decide, panel.add(28, ""))

    out = show(tmp_path, capsys, build)
    start = next(i for i, line in enumerate(out) if line.endswith("  If"))
    first = out[start + 1]
    assert first.startswith("          out 0 if state.Status")
    block = [first]
    for line in out[start + 2 :]:
        if not line.startswith(" " * 14):
            break
        block.append(line)
    assert len(block) >= 2  # wrapped, not cut
    assert " ".join(part.strip() for part in block).removeprefix("out 0 if ") == CONDITION
    assert out[start + 1 + len(block)] == "          out 1 if value > 0"
    assert "          out 0 -> " in out[start + 2 + len(block)]


def test_code_is_a_block_of_its_own(tmp_path, capsys):
    def build(panel):
        raw = panel.add(52, "Robot/IoT Controller 0", "-1")
        code = panel.add(44, "Reader", CODE, "Newtonsoft.Json.dll")
        panel.chain(raw, code, panel.add(28, ""))

    out = show(tmp_path, capsys, build)
    head = next(i for i, line in enumerate(out) if "Code Activity:" in line)
    assert out[head].endswith("Code Activity: class Reader, run as the sensor-JSON built-in")
    assert out[head + 1] == "          references: Newtonsoft.Json.dll"
    assert out[head + 2] == "          C#, 7 lines:"
    block = out[head + 3 : head + 10]
    assert all(line.startswith("          |") for line in block)
    assert [line.removeprefix("          | ") for line in block] == [
        line.expandtabs(4) for line in CODE.splitlines()
    ]
    assert out[head + 10].startswith("          out 0 -> ")
    # no line of the code appears anywhere but in its block
    assert sum("JObject.Parse" in line for line in out) == 1


def test_long_text_is_cut_saying_so(tmp_path, capsys):
    def build(panel):
        panel.add(11, "word " * 2000)

    out = show(tmp_path, capsys, build)
    assert "          ... (cut: 10,000 characters; the first 12 lines are shown)" in out


def test_printed_text_from_a_robot_cannot_drive_the_terminal():
    assert one_line("red \x1b[31mtext\rover\nnext", 60) == "red \\x1b[31mtext\\x0dover\\nnext"
    assert one_line("x" * 100, 20) == "x" * 17 + "..."


def test_counts_are_singular_and_plural_as_they_should_be(tmp_path, capsys):
    b = ProgramBuilder()
    b.panel("Main").add(3, "1")
    path = b.write(tmp_path / "one.viple")
    assert main(["viple", "show", path]) == 0
    assert "\n1 panel, 1 activity, 0 links\n" in capsys.readouterr().out
    assert main(["viple", "check", path]) == 0
    assert "ok (VIPLE 4.0.0.1, 1 activity, 1 panel, 0 links)" in capsys.readouterr().out


def spin_program(tmp_path) -> str:
    b = ProgramBuilder()
    panel = b.panel("Main")
    b.robot(panel)
    key = panel.add(13, "22")
    panel.chain(key, panel.add(20, "0.5", "-0.5", "R", "3", "5"))
    panel.chain(key, panel.add(3, '"spinning"'), panel.add(28, ""))
    panel.chain(panel.add(29, ""), panel.add(20, "0", "0", "R", "3", "5"))
    return b.write(tmp_path / "spin.viple")


def test_run_words_turns_degrees_and_one_line_truly(tmp_path, capsys):
    path = spin_program(tmp_path)
    args = ["viple", "run", path, "--maze", WEB_MAZE, "--max-time", "3"]
    main([*args, "--keys", "w@0.5 release@1.5"])
    out = capsys.readouterr().out
    turning = re.search(r"turning degrees +(\d+) deg in all; (.*)", out)
    assert turning and int(turning.group(1)) > 45
    assert turning.group(2) == "1 turn of 45 deg or more"
    assert "  printed 1 line:\n       0.50 s  spinning\n" in out
    assert "  events: 2:\n" in out
    main([*args, "--keys", "w@0.5 release@0.55"])
    out = capsys.readouterr().out
    turning = re.search(r"turning degrees +(\d+) deg in all; (.*)", out)
    assert turning and int(turning.group(1)) < 45
    assert turning.group(2) == "0 turns of 45 deg or more"
    # cut by the time limit: said of the program's flows, never as an algorithm's state
    assert "(the run was cut; 0 flows of the program still going)" in out


def test_the_printed_summary_shows_the_true_first_and_last_lines(tmp_path):
    """Far more lines than a run keeps: the last lines shown are the run's last, and the
    lines between are counted with their simulated times."""
    b = ProgramBuilder()
    panel = b.panel("Main")
    b.robot(panel)
    panel.chain(panel.add(23, "R", "3"), panel.add(28, ""))
    controller = ProgramController(
        load_compiled(b.write(tmp_path / "p.viple")), parse_key_script("")
    )
    controller.start(0.0)
    ticks = MAX_PRINTED + 3_000
    for i in range(1, ticks + 1):
        controller.tick(i * 0.05, {"port 3": i}, frozenset())
    assert controller.printed_total == ticks and controller.printed_dropped == 3_000
    lines = printed_summary(controller)
    assert lines[0] == f"  printed {ticks:,} lines; the first 5 and the last 10:"
    shown = [int(line.split()[-1]) for line in lines[1:6] + lines[7:]]
    assert shown == [1, 2, 3, 4, 5, *range(ticks - 9, ticks + 1)]
    assert lines[6] == (
        f"    ... {ticks - 15:,} lines not shown (lines 6 to {ticks - 10:,}, printed from "
        f"{6 * 0.05:.2f} s to {(ticks - 10) * 0.05:.2f} s)"
    )
    assert lines[7].startswith(f"    {(ticks - 9) * 0.05:7.2f} s  ")
