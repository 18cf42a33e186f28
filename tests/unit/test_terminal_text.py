"""Names and texts that reach a terminal never carry control characters: the ones in files a
person gives are refused at load with their place, everything else is printed escaped
(issue 37)."""

from __future__ import annotations

import json
import re
import unicodedata

import pytest
from hypothesis import given
from hypothesis import strategies as st

from workbench.cli import main
from workbench.files.terminal import terminal_problem, terminal_safe, terminal_safe_data
from workbench.fsm.yaml_file import FsmFileError, loads_fsm
from workbench.labs.model import LabFileError, load_lab
from workbench.program.loader import load_program_text
from workbench.program.problems import ProgramError
from workbench.sim.mazefile import MazeError, parse_maze

RAW = re.compile("[\x00-\x1f\x7f-\x9f]")
#: the YAML spelling of a title change and a clipboard write
YAML_TITLE = r'"Hall \e]0;PWNED\e\\ \e]52;c;aGk=\a maze"'
MAZE = "---\nname: {name}\n---\n#####\n#S.E#\n#####\n"
FSM = """name: {name}
sensors:
  front: {{kind: distance, mount: front}}
initial: go
states:
  go:
    do: forward
"""


def test_terminal_safe_writes_every_control_out():
    assert terminal_safe("a\x1b]0;X\x1b\\b") == "a\\x1b]0;X\\x1b\\b"
    assert terminal_safe("\x9b2J\x7f\u202e") == "\\x9b2J\\x7f\\u202e"
    assert terminal_safe("two\nlines\tand\r", multiline=True) == "two\nlines\tand\\x0d"
    assert terminal_safe("two\nlines") == "two\\x0alines"
    assert terminal_safe_data({"maze\x1b": ["a\x07", 3, None]}) == {
        "maze\\x1b": ["a\\x07", 3, None]
    }


@given(st.text())
def test_no_text_is_printed_with_a_control_in_it(text):
    shown = terminal_safe(text)
    assert not any(unicodedata.category(c) == "Cc" for c in shown)
    assert not RAW.search(terminal_safe(text, multiline=True).replace("\n", "").replace("\t", ""))
    assert (terminal_problem(text, "it") == "") == (RAW.search(text) is None)


def test_a_maze_name_with_a_title_escape_is_refused_with_its_place():
    with pytest.raises(MazeError) as caught:
        parse_maze(MAZE.format(name=YAML_TITLE), "hall.txt")
    (problem,) = caught.value.problems
    assert (problem.line, problem.column) == (2, 7)
    assert "'name' holds an escape character (ESC)" in problem.message
    assert "position 6" in problem.message and "remove it" in problem.hint


def test_an_fsm_name_with_a_title_escape_is_refused_with_its_place():
    with pytest.raises(FsmFileError) as caught:
        loads_fsm(FSM.format(name=YAML_TITLE), "walls.yaml")
    text = str(caught.value)
    assert "walls.yaml:1:7" in text and "'name' holds an escape character" in text
    assert "\x1b" not in text


def test_a_lab_title_with_a_control_is_refused_with_its_place(tmp_path):
    lab = tmp_path / "lab.yaml"
    lab.write_text('id: l1\ntitle: "Lab \\x9b2J one"\nexercises: []\n')
    with pytest.raises(LabFileError) as caught:
        load_lab(lab)
    text = str(caught.value)
    assert "lab.yaml:2:8" in text and "control sequence introducer" in text
    assert "\x9b" not in text


def test_a_viple_name_given_as_a_character_reference_is_refused_with_its_place():
    text = '<?xml version="1.0"?>\n<Program>\n  <ProgrammingPanel Name="Main&#x9b;2J">\n'
    with pytest.raises(ProgramError) as caught:
        load_program_text(text + "</ProgrammingPanel></Program>\n", "walls.viple")
    words = str(caught.value)
    assert "line 3, column 31" in words and "&#x9b;" in words and "\x9b" not in words


@given(
    st.characters(min_codepoint=0, max_codepoint=0x9F).filter(lambda c: RAW.match(c) is not None)
)
def test_maze_check_never_prints_a_control_from_a_name(tmp_path_factory, control):
    """Whatever control a maze name spells with a YAML escape, ``maze check`` refuses it and
    prints nothing raw."""
    if control in "\t\n":
        return  # kept in texts that run over lines (and YAML folds them in a name)
    folder = tmp_path_factory.mktemp("maze")
    path = folder / "m.txt"
    path.write_text(MAZE.format(name=json.dumps(f"a{control}b")))
    out = _run(["maze", "check", str(path)])
    assert "INVALID" in out and not RAW.search(out.replace("\n", ""))


def _run(argv: list[str]) -> str:
    import contextlib
    import io

    buffer = io.StringIO()
    with contextlib.redirect_stdout(buffer):
        main(argv)
    return buffer.getvalue()


def test_maze_check_prints_a_file_name_with_an_escape_escaped(tmp_path, capsys):
    path = tmp_path / "hall\x1b]0;PWNED\x07.txt"
    path.write_text(MAZE.format(name="Hall"))
    assert main(["maze", "check", str(path)]) == 0
    out = capsys.readouterr().out
    assert "\x1b" not in out and "\x07" not in out
    assert "hall\\x1b]0;PWNED\\x07.txt: valid - Hall" in out


def test_a_run_record_with_an_escape_in_its_header_is_refused_with_its_place(tmp_path):
    from workbench.sim.record import FORMAT, RecordError, read_record

    path = tmp_path / "run-001.jsonl"
    header = {"type": "header", "format": FORMAT, "maze": {"name": "Hall\x1b]0;PWNED\x07"}}
    path.write_text(json.dumps(header) + "\n" + json.dumps({"t": 0.0, "pose": [1, 1, 0]}) + "\n")
    with pytest.raises(RecordError) as caught:
        read_record(path)
    words = str(caught.value)
    assert f"{path}:1: maze.name holds an escape character (ESC)" in words
    assert "changed after it was written" in words and "\x1b" not in words


def _texts(value):
    if isinstance(value, str):
        yield value
    elif isinstance(value, dict):
        for key, item in value.items():
            yield from _texts(key)
            yield from _texts(item)
    elif isinstance(value, list):
        for item in value:
            yield from _texts(item)


evidence = st.recursive(
    st.text() | st.integers() | st.none(),
    lambda inner: st.lists(inner, max_size=3) | st.dictionaries(st.text(), inner, max_size=3),
    max_leaves=12,
)


@given(evidence)
def test_saved_evidence_is_handed_to_the_console_without_a_raw_control(value):
    for text in _texts(terminal_safe_data(value)):
        assert not RAW.search(text.replace("\n", "").replace("\t", ""))


def test_a_name_runs_on_one_line():
    with pytest.raises(MazeError, match="the maze's name holds a control character"):
        parse_maze(MAZE.format(name='"Hall\\nmaze"'), "hall.txt")
    with pytest.raises(FsmFileError, match="the FSM's name holds a control character"):
        loads_fsm(FSM.format(name='"walls\\tfirst"'), "walls.yaml")
    parse_maze("---\nname: Hall\ndescription: |\n  two\n  lines\n---\n#####\n#S.E#\n#####\n")


def test_the_command_line_s_output_keeps_its_lines_and_writes_controls_out():
    import io

    from workbench.files.terminal import TerminalSafeWriter

    out = io.StringIO()
    TerminalSafeWriter(out).write("a,b\r\nc\td\n\x1b[2J\rx")
    assert out.getvalue() == "a,b\r\nc\td\n\\x1b[2J\\x0dx"
