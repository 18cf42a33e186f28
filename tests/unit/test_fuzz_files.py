"""Fuzzing the readers of untrusted text: only their documented errors ever come out."""

from __future__ import annotations

import contextlib

import yaml
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from workbench.files.bounded import BoundedFileError, Limits, compose_yaml, decode_text
from workbench.fsm.expr import ExprError, compile_expr
from workbench.fsm.yaml_file import FsmFileError, loads_fsm
from workbench.sim.maze import MazeError
from workbench.sim.mazefile import parse_maze
from workbench.sim.micromouse import parse_micromouse, parse_mms_map, parse_mms_num

SMALL = Limits("a test file", max_bytes=4_000, max_lines=40, max_line_length=200, max_depth=6)
FUZZ = settings(max_examples=300, deadline=None, suppress_health_check=[HealthCheck.too_slow])

#: pieces that make the readers' special cases likely
MAZE_BITS = st.sampled_from(
    ["#", ".", " ", "S", "E", "^", "\n", "---\n", "name: ", "cell: ", ".nan", "[", "{", "&a ",
     "*a", "\t", "\0", "\ufeff", "Z", "o", "---", "|", "+", "1", "0 ", "9" * 40]
)  # fmt: skip
EXPR_BITS = st.sampled_from(
    ["x", "1", "1e999", "(", ")", "-", "+", "not ", " and ", " or ", "<", "==", "abs(", ",",
     "'", '"', "\\", ".", "9" * 35, "*", "/", " ", "min(", "lambda", "[", "**", "~"]
)  # fmt: skip

YAML_BITS = st.sampled_from(
    ["[", "{", "a: ", "- ", "&x ", "*x", "\n", " ", ".nan", "1", ",", "]", "}", "\0"]
)
FSM_BITS = st.sampled_from(
    ["name: a\n", "states:\n", "  S:\n", "    on_enter:\n", "      - move: ", "x\n", "[",
     "-" * 60, "not " * 30, "1e999\n", ".nan\n", "&a ", "*a\n", "\0", "initial: S\n"]
)  # fmt: skip


@FUZZ
@given(st.binary(max_size=600))
def test_decode_text_raises_only_its_own_error(data):
    try:
        text = decode_text(data, "f", SMALL)
    except BoundedFileError as exc:
        assert exc.path == "f"
        return
    assert isinstance(text, str) and not text.startswith("\ufeff")


@FUZZ
@given(st.lists(YAML_BITS, max_size=80))
def test_compose_yaml_raises_only_limits_or_yaml_errors(parts):
    with contextlib.suppress(BoundedFileError, yaml.YAMLError):
        compose_yaml("".join(parts), "f", SMALL)


@FUZZ
@given(st.one_of(st.text(max_size=400), st.lists(MAZE_BITS, max_size=120).map("".join)))
def test_maze_parsers_raise_only_maze_errors(text):
    for parse in (parse_maze, parse_micromouse, parse_mms_map, parse_mms_num):
        try:
            parse(text)
        except MazeError as exc:
            assert exc.problems


@FUZZ
@given(st.one_of(st.text(max_size=200), st.lists(EXPR_BITS, max_size=150).map("".join)))
def test_compile_expr_raises_only_expr_errors(text):
    with contextlib.suppress(ExprError):
        compile_expr(text, {"x"})


@FUZZ
@given(st.lists(FSM_BITS, max_size=40))
def test_fsm_text_raises_only_fsm_file_errors(parts):
    try:
        loads_fsm("".join(parts), "f.yaml")
    except FsmFileError as exc:
        assert exc.problems
