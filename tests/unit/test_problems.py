"""One shape of problem for every file a user gives, and one expression error: each reader's
problems still read as they did, with their place (file, line, column) where users look."""

from __future__ import annotations

import pytest

from workbench.cli.maze import check_report
from workbench.files.problems import ExprError, Problem
from workbench.fsm.expr import compile_expr
from workbench.fsm.yaml_file import FsmFileError, loads_fsm
from workbench.program import viple_expr
from workbench.program.problems import program_problem
from workbench.sim.maze import MazeError
from workbench.sim.mazefile import parse_maze

FSM = """name: t
initial: A
states:
  A:
    transitions:
      - {when: "front < 1 +* 2", to: A}
"""


def test_a_maze_problem_names_file_line_and_column_and_its_json_keeps_its_keys():
    with pytest.raises(MazeError) as info:
        parse_maze("#####\n#S.x#\n#####\n", source="m.txt")
    (problem,) = info.value.problems
    assert str(problem) == "m.txt:2:4: unknown character 'x' (use # wall, . floor, S start, E exit)"
    assert (problem.source, problem.line, problem.column) == ("m.txt", 2, 4)
    report = check_report(None, [Problem("no maze grid found", "draw it", "e.txt")], "e.txt")
    assert report["problems"] == [
        {"source": "e.txt", "line": None, "col": None, "message": "no maze grid found",
         "hint": "draw it"}
    ]  # fmt: skip


def test_an_fsm_files_problem_points_into_the_expression_with_a_labelled_hint():
    with pytest.raises(FsmFileError) as info:
        loads_fsm(FSM, "t.yaml")
    (problem,) = info.value.problems
    assert (problem.message, problem.line, problem.column) == (
        "bad syntax: invalid syntax",
        6,
        28,
    )
    assert str(problem).startswith("t.yaml:6:28: bad syntax: invalid syntax (hint: ")


def test_a_problem_in_a_definition_or_a_program_names_its_part():
    key = Problem("unknown mount 'top'", "use one of front", path=("sensors", "front", "mount"))
    assert str(key) == "sensors.front.mount: unknown mount 'top' (use one of front)"
    listed = Problem("too few", path=("states", "A", "transitions", 0))
    assert str(listed) == "states.A.transitions[0]: too few"
    act = program_problem("p.viple", "it reads port 3", "add one", "Main", 12, 23, "front")
    assert (
        str(act) == "p.viple: panel Main: activity 12 (kind 23, front): it reads port 3 (add one)"
    )
    assert str(program_problem("p.viple", "not a program")) == "p.viple: not a program"


def test_one_expression_error_reads_as_each_language_shows_it():
    with pytest.raises(ExprError) as fsm:
        compile_expr("1 +* 2", names={"front"})
    assert str(fsm.value).startswith("bad syntax: invalid syntax in '1 +* 2' at column 4 (")
    with pytest.raises(ExprError) as program:
        viple_expr.parse("1 +* 2")
    assert str(program.value) == "column 4: expected a value but found '*'"
    assert issubclass(viple_expr.LimitError, ExprError)
    long = ExprError("too long", 70, text="x" * 80)
    assert str(long) == f"too long in '{'x' * 57}...' at column 70"
