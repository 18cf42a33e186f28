"""Expressions past the limits are refused with a column, before the parser recurses."""

from __future__ import annotations

import pytest

from workbench.fsm.expr import MAX_DEPTH, ExprError, compile_expr


def refused(text: str) -> ExprError:
    with pytest.raises(ExprError) as info:
        compile_expr(text, {"x"})
    return info.value


@pytest.mark.parametrize(
    ("text", "column", "message"),
    [
        ("+".join(["x"] * 500), 1, "the expression has 999 values and operators; at most 200"),
        ("not " * 500 + "x", 2_001, "the expression is 2,001 characters long; at most 2,000"),
        ("not " * 400 + "x", 201, "brackets and unary operators nest more than 50 deep"),
        ("-" * 100_000 + "1", 2_001, "the expression is 100,001 characters long; at most 2,000"),
        ("-" * 1_999 + "1", 51, "brackets and unary operators nest more than 50 deep"),
        ("(" * 60 + "x" + ")" * 60, 51, "brackets and unary operators nest more than 50 deep"),
        ("x < " + "1" * 5_000, 2_001, "the expression is 5,004 characters long; at most 2,000"),
        ("x < " + "1" * 1_000, 5, "a number with 1,000 digits; numbers have at most 30"),
        ("x < 0." + "1" * 40, 5, "a number with 41 digits; numbers have at most 30"),
        ("x < 1e999", 5, "the number is too large (not finite)"),
        ("x < 1e308 * 10", 5, "the result is too large (not finite)"),
    ],
    ids=[
        "500-terms",
        "500-nots",
        "400-nots",
        "100k-minus",
        "1999-minus",
        "60-brackets",
        "5000-digits",
        "1000-digits",
        "41-decimals",
        "inf",
        "folded-inf",
    ],
)
def test_limits_are_refused_with_a_clear_message_and_column(text, column, message):
    err = refused(text)
    assert err.message == message
    assert err.column == column
    assert len(str(err)) < 300  # the expression is shown cut short


def test_a_long_flat_chain_is_refused_as_too_deep_not_by_a_crash():
    err = refused(" + ".join(["x"] * 60))
    assert err.message.startswith(f"the expression nests more than {MAX_DEPTH} levels")


@pytest.mark.parametrize(
    "text",
    [
        " and ".join(["not x"] * 60),
        "x == '" + "(" * 100 + "'",
        "max(" + ", ".join(["x"] * 90) + ")",
        "-" * 40 + "x",
        "(" * 40 + "x" + ")" * 40,
        "x < " + "1" * 30,
        " + ".join(["x"] * 40),
    ],
    ids=["not-chain", "string", "call", "40-minus", "40-brackets", "30-digits", "40-terms"],
)
def test_within_the_limits_still_compiles(text):
    compile_expr(text, {"x"})({"x": 1})
