"""VIPLE's expression language: precedence, keywords in any case, text, C# numbers, errors."""

from __future__ import annotations

import contextlib
import math
import re
from decimal import Decimal

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from workbench.program.viple_expr import (
    MAX_DEPTH,
    ExprError,
    Scope,
    literal,
    parse,
    show,
    show_double,
)

SCOPE = Scope(
    value=25,
    state={"status": "Forward", "basedistance": 20, "left": 6.0},
    instance={"time": 200},
    parts={"leftpower": 0.5, "rightpower": -0.5},
)


@pytest.mark.parametrize(
    ("text", "expected"),
    [
        ("1 + 2 * 3", 7),
        ("(1 + 2) * 3", 9),
        ("10 - 4 - 3", 3),
        ("7 / 2", 3),
        ("-7 / 2", -3),
        ("7 % -2", 1),
        ("7 mod 4", 3),
        ("7 / 2.0", 3.5),
        ("1 + 2 < 4 && 2 * 2 == 4", True),
        ("true || false && false", True),
        ("!true || true", True),
        ("not (1 = 1) or 2 <> 3", True),
        ('1 < 2 ? "yes" : "no"', "yes"),
        ("iif(value > 30, 1, 2)", 2),
        ("false ? 1 : true ? 2 : 3", 2),
        ("-value + 5", -20),
        ("Math.Abs(-2.5) + Math.Max(1, 2)", 4.5),
        ('Convert.ToInt32("42") + 1', 43),
    ],
)
def test_precedence_and_numbers(text, expected):
    result = parse(text)(SCOPE)
    assert result == expected and type(result) is type(expected)


@pytest.mark.parametrize(
    ("text", "expected"),
    [
        ('state.Status == "Forward" AND value < state.BaseDistance - 5', False),
        ('STATE.status == "Forward" and VALUE > state.basedistance + 4', True),
        ("state.left<6.5", True),
        ("instance.time + 1", 201),
        ("leftPower - RightPower", 1.0),
        ("IT == 25 And True", True),
    ],
)
def test_names_and_keywords_ignore_case(text, expected):
    assert parse(text)(SCOPE) == expected


@pytest.mark.parametrize(
    ("text", "expected"),
    [
        ('"Front sensor value: " + value', "Front sensor value: 25"),
        ('state.left + " " + 1.5', "6 1.5"),
        ('"a" + 1 + 2', "a12"),
        ('1 + 2 + "a"', "3a"),
        ('"x" & true', "xTrue"),
        ('\'c\' + """q"""', 'c"q"'),
    ],
)
def test_plus_with_text_joins_text_as_csharp_shows_values(text, expected):
    assert parse(text)(SCOPE) == expected


@pytest.mark.parametrize(
    ("text", "column", "message"),
    [
        ("value < ", 9, "expected a value but found the end"),
        ("value # 3", 7, "has no meaning here"),
        ("(1 + 2", 7, "expected ')'"),
        ("1 2", 3, "unexpected '2'"),
        ("Math.Cube(2)", 6, "unknown function 'Cube'"),
        ("iif(true, 1)", 1, "iif takes 3 values, not 2"),
        ("", 1, "the expression is empty"),
    ],
)
def test_syntax_errors_give_the_column(text, column, message):
    with pytest.raises(ExprError) as info:
        parse(text)
    assert info.value.column == column and message in str(info.value)


@pytest.mark.parametrize(
    ("text", "column", "message"),
    [
        ("value / 0", 7, "division by zero"),
        ('value < "x"', 7, "< cannot compare Int32 with String"),
        ("value && true", 7, "&& needs true or false, not Int32"),
        ("state.nothing", 7, "there is no global variable 'nothing'"),
        ("speed + 1", 1, "unknown name 'speed'"),
    ],
)
def test_evaluation_errors_give_the_column(text, column, message):
    expression = parse(text)
    with pytest.raises(ExprError) as info:
        expression(Scope(value=3))
    assert info.value.column == column and message in str(info.value)


def test_sizes_are_bounded_before_parsing():
    with pytest.raises(ExprError, match="nested more than"):
        parse("(" * (MAX_DEPTH + 5) + "1" + ")" * (MAX_DEPTH + 5))
    with pytest.raises(ExprError, match="at most 2,000"):
        parse("1+" * 1500 + "1")
    with pytest.raises(ExprError, match="digits"):
        parse("1" * 40)


def test_names_read_are_listed_for_the_checks():
    e = parse('state.Status == "x" && instance.Time > leftPower')
    assert e.state_names == {"status"} and e.instance_names == {"time"}
    assert e.bare_names == {"leftpower"}


@pytest.mark.parametrize(
    ("text", "value"),
    [
        ("20", 20),
        ("0.0", 0.0),
        ("-1.5", -1.5),
        ('"look"', "look"),
        ("look", "look"),
        ('""', ""),
        ("true", True),
        ("Turning left 90", "Turning left 90"),
    ],
)
def test_data_literals(text, value):
    result = literal(text)
    assert result == value and type(result) is type(value)


def test_values_show_as_csharp_prints_them():
    assert [show(1.0), show(0.5), show(True), show(None), show(7)] == ["1", "0.5", "True", "", "7"]


@pytest.mark.parametrize(
    ("value", "text"),
    [
        # the examples of .NET's Double.ToString() documentation
        (1.6e20, "1.6E+20"),
        (1.6e2, "160"),
        (-3.541, "-3.541"),
        (-1502345222199e-07, "-150234.5222199"),
        (-15023452221990199574e-09, "-15023452221.9902"),
        (0.60344, "0.60344"),
        (0.000000001, "1E-09"),
        # 15 significant digits, not the 17 a round trip needs
        (0.1 + 0.2, "0.3"),
        (1 / 3, "0.333333333333333"),
        (2 / 3, "0.666666666666667"),
        (123456789012345.6, "123456789012346"),
        # fixed point for exponents -4 to 14, else E with a sign and two digits or more
        (1e21, "1E+21"),
        (1e15, "1E+15"),
        (999999999999999.0, "999999999999999"),
        (999999999999999.9, "1E+15"),
        (0.0001, "0.0001"),
        (0.00001, "1E-05"),
        (-2.5e-7, "-2.5E-07"),
        (1.7976931348623157e308, "1.79769313486232E+308"),
        (5e-324, "4.94065645841247E-324"),
        (2.0, "2"),
        (-0.0, "0"),
        (math.nan, "NaN"),
        (math.inf, "Infinity"),
        (-math.inf, "-Infinity"),
    ],
)
def test_reals_print_as_dotnet_writes_a_double(value, text):
    assert show_double(value) == text
    assert show(value) == text


@pytest.mark.parametrize(
    ("expression", "text"),
    [
        ('"sum " + (0.1 + 0.2)', "sum 0.3"),
        ('"big " + 1.0E21', "big 1E+21"),
        ("Convert.ToString(1.0 / 3.0)", "0.333333333333333"),
        ('0.5 * 0.2 + ""', "0.1"),
    ],
)
def test_text_made_of_reals_reads_as_in_viple(expression, text):
    assert parse(expression)(SCOPE) == text


_FIXED = re.compile(r"-?(0|[1-9]\d*)(\.\d*[1-9])?")
_EXPONENT = re.compile(r"-?[1-9](\.\d*[1-9])?E[+-]\d{2,3}")


@settings(max_examples=2000)
@given(st.floats(allow_nan=False, allow_infinity=False))
def test_every_finite_double_reads_back_to_its_15_digits(x):
    text = show_double(x)
    assert float(text) == float(f"{x:.14e}")  # the value rounded to 15 significant digits
    digits = re.sub(r"E.*", "", text).replace("-", "").replace(".", "").strip("0")
    assert len(digits) <= 15
    exponent = Decimal(text).adjusted()  # the decimal exponent of what is written
    if -4 <= exponent <= 14:
        assert _FIXED.fullmatch(text), text
    else:
        assert _EXPONENT.fullmatch(text), text


_ATOMS = st.sampled_from(
    [
        "value",
        "state.x",
        "instance.y",
        "1",
        "2.5",
        '"s"',
        "'c'",
        "true",
        "null",
        "iif",
        "Math.Abs",
        "Convert.ToInt32",
        "joinName",
        "it",
    ]
)
_OPS = st.sampled_from(
    [
        "+",
        "-",
        "*",
        "/",
        "%",
        "mod",
        "&&",
        "||",
        "and",
        "or",
        "not",
        "!",
        "==",
        "=",
        "<>",
        "!=",
        "<",
        "<=",
        ">",
        ">=",
        "?",
        ":",
        "(",
        ")",
        ",",
        ".",
        "&",
        " ",
    ]
)


@settings(max_examples=400, deadline=None)
@given(st.lists(st.one_of(_ATOMS, _OPS), max_size=30))
def test_fuzz_token_soup_raises_only_expr_error(parts):
    text = " ".join(parts)
    try:
        expression = parse(text)
        expression(Scope(value=3, state={"x": 2.0}, instance={"y": "t"}, parts={"joinname": 1}))
    except ExprError:
        pass


@settings(max_examples=300, deadline=None)
@given(st.text(max_size=120))
def test_fuzz_any_text_raises_only_expr_error(text):
    with contextlib.suppress(ExprError):
        parse(text)(Scope(value="v"))


_SAMPLES = [0, 5, 7, -2, 5.0, 2.5, "5", "a", "b", "", True, False, None]
_OPS = ["==", "=", "!=", "<>", "<", "<=", ">", ">="]


def _outcome(text: str, scope: Scope):
    try:
        return ("value", parse(text)(scope))
    except ExprError as exc:
        return ("error", str(exc))


@pytest.mark.parametrize("op", _OPS)
def test_a_comparison_with_a_literal_gives_what_it_gives_with_the_same_value_in_a_variable(op):
    """A literal's side of a comparison is known when it is parsed; every pair of values
    compares (or fails, with the same words) as when neither side is known."""
    literals = ["0", "5", "7", "-2", "5.0", "2.5", '"5"', '"a"', '""', "true", "false", "null"]
    for text in literals:
        known = literal(text) if text not in ("true", "false", "null") else None
        for sample in _SAMPLES:
            scope = Scope(value=sample, state={"x": known})
            as_literal = _outcome(f"value {op} {text}", scope)
            if text in ("true", "false", "null"):
                other = Scope(value=sample, state={"x": {"true": True, "false": False}.get(text)})
            else:
                other = scope
            assert as_literal == _outcome(f"value {op} state.x", other), (text, sample)
            # a global against the literal: as the value against it (the same columns)
            global_scope = Scope(value=None, state={"v": sample})
            padded = _outcome(f"value   {op} {text}", scope)  # as wide as state.v
            assert padded == _outcome(f"state.v {op} {text}", global_scope), (text, sample)
            # the literal written as wide as state.x, so that errors name the same column
            left = f"{text:<7} {op} value"
            assert _outcome(left, scope) == _outcome(f"state.x {op} value", other), (text, sample)


def test_a_comparison_of_two_numbers_or_two_texts_and_its_errors():
    assert parse('value == "fwd" && value != "x"')(Scope(value="fwd")) is True
    assert parse("value > 75")(Scope(value=75.5)) is True
    assert parse("value >= 2")(Scope(value=2)) is True
    assert parse('"b" > value')(Scope(value="a")) is True
    assert parse("value == null")(Scope(value=None)) is True
    with pytest.raises(ExprError, match="< cannot compare Boolean with Int32"):
        parse("value < 5")(Scope(value=True))
    with pytest.raises(ExprError, match="> cannot compare String with Int32"):
        parse("value > 5")(Scope(value="a"))
    with pytest.raises(ExprError, match="column 7: there is no global variable 'Mode'"):
        parse('state.Mode == "fwd"')(Scope(value=1, state={}))


@pytest.mark.parametrize(
    ("text", "value", "expected"),
    [
        ("value > 1 && value < 3", 2, True),
        ("value > 1 && value < 3", 0, False),
        ("value < 1 || value > 3", 4, True),
        ("value < 1 || value > 3", 2, False),
        ("value < 1 || value > 3", 0, True),
        ("value > 1 && value", 0, False),
        ("value < 1 || value", 0, True),
    ],
)
def test_and_and_or_stop_at_the_first_side_that_decides(text, value, expected):
    assert parse(text)(Scope(value=value)) is expected


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("value && true", "column 7: && needs true or false, not Int32"),
        ("true && value", "column 6: && needs true or false, not Int32"),
        ("value || true", "column 7: || needs true or false, not Int32"),
        ("false || value", "column 7: || needs true or false, not Int32"),
    ],
)
def test_and_and_or_need_true_or_false_on_the_side_they_read(text, message):
    with pytest.raises(ExprError) as caught:
        parse(text)(Scope(value=3))
    assert message in str(caught.value)


def test_a_negated_number_literal_is_a_literal_and_a_negated_text_still_fails_as_it_runs():
    for text, value in (("-0.2", -0.2), ("--3", 3), ("-(1.5)", -1.5), ("- 0", 0)):
        expression = parse(text)
        assert expression.tree is not None and expression.tree.kind == "literal"
        assert expression.tree.data == (value,)
        assert expression.run(SCOPE) == value and type(expression.run(SCOPE)) is type(value)
    # a comparison with it compares as with the value itself
    assert parse("value > -30").run(SCOPE) is True
    assert parse("-value").tree.kind != "literal"
    wrong = parse('-"a"')
    assert wrong.tree is None or wrong.tree.kind != "literal"
    with pytest.raises(ExprError, match="- needs a number, not String"):
        wrong.run(SCOPE)
