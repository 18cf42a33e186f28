"""The guard/action expression language: what it computes and what it refuses, with where."""

import pytest

from workbench.fsm.expr import ExprError, compile_expr


def value(text, **env):
    return compile_expr(text, names=set(env))(env)


@pytest.mark.parametrize(
    ("text", "env", "expected"),
    [
        ("front < 50", {"front": 49.9}, True),
        ("front < 50", {"front": 50}, False),
        ("right > base + 50", {"right": 76, "base": 25}, True),
        ("0 < right <= 40", {"right": 40}, True),
        ("0 < right <= 40", {"right": 0}, False),
        ("1 < 2 < x", {"x": 2}, False),
        ("turn_done and timer_done", {"turn_done": True, "timer_done": False}, False),
        ("turn_done or timer_done", {"turn_done": False, "timer_done": True}, True),
        ("not turn_done", {"turn_done": False}, True),
        ("-(a - b) * 2 / 4", {"a": 1, "b": 3}, 1.0),
        ("+a", {"a": 3}, 3),
        ("abs(a - b)", {"a": 1, "b": 4}, 3),
        ("min(a, b, 7)", {"a": 9, "b": 8}, 7),
        ("max(a, 2)", {"a": 1}, 2),
        ('Status == "Forward"', {"Status": "Forward"}, True),
        ("Status != 'Forward'", {"Status": "Turning"}, True),
        ("(a + b) * c", {"a": 1, "b": 2, "c": 3}, 9),
        ("True", {}, True),
        ("a >= b", {"a": 2.0, "b": 2}, True),
    ],
)
def test_values(text, env, expected):
    assert value(text, **env) == expected


def test_compiled_once_evaluated_many_times_with_fresh_values():
    guard = compile_expr("front < limit", names={"front", "limit"})
    assert [guard({"front": f, "limit": 50}) for f in (10, 60, 49)] == [True, False, True]
    assert guard.names == {"front", "limit"}
    assert guard.text == "front < limit"


def test_constants_are_folded_but_still_listed_as_read():
    guard = compile_expr("front < limit", names={"front"}, constants={"limit": 50.0})
    assert guard({"front": 49}) is True
    assert "limit" in guard.names
    whole = compile_expr("2 * limit + 1", names=set(), constants={"limit": 3})
    assert whole.constant and whole() == 7


@pytest.mark.parametrize(
    ("text", "column", "message", "hint"),
    [
        ("frnt < 50", 1, "unknown name 'frnt'", "did you mean 'front'?"),
        ("front < 50 and rigth > 2", 16, "unknown name 'rigth'", "did you mean 'right'?"),
        ("sensor.value > 3", 1, "attribute access", "plain names"),
        ("front.__class__", 1, "attribute access", ""),
        ("readings[0] > 3", 1, "indexing", ""),
        ('__import__("os")', 1, "unknown function '__import__'", "abs(x)"),
        ("open('x')", 1, "unknown function 'open'", "abs(x)"),
        ("front(3)", 1, "unknown function 'front'", ""),
        ("lambda: 1", 1, "lambda is not allowed", ""),
        ("front ** 2 > 4", 7, "the operator ** is not allowed", "x * x"),
        ("front % 2", 7, "the operator % is not allowed", ""),
        ("front in (1, 2)", 7, "the comparison 'in' is not allowed", ""),
        ("1 if front else 2", 1, "'x if c else y' is not allowed", "two transitions"),
        ("[front]", 1, "lists are not allowed", ""),
        ("None", 1, "the value None is not allowed", ""),
        ("true", 1, "unknown name 'true'", "write True"),
        ("abs", 1, "abs is a function", "abs(x)"),
        ("min(front)", 1, "min() takes at least 2 arguments, not 1", ""),
        ("abs(front, 1)", 1, "abs() takes exactly 1 argument, not 2", ""),
        ("max(a=front, b=2)", 1, "takes no keyword arguments", ""),
        ("front / 0", 7, "division by zero", ""),
        ("(front := 3)", 2, "':=' is not allowed", ""),
        ("x && y", None, "bad syntax", "write 'and' / 'or'"),
        ("front = 3", 7, "bad syntax", "compare with =="),
        ("(front < 3", None, "bad syntax", "every '('"),
        ("", None, "empty expression", ""),
    ],
)
def test_refused_with_column_and_hint(text, column, message, hint):
    with pytest.raises(ExprError) as info:
        compile_expr(text, names={"front", "right", "a", "x", "y"})
    err = info.value
    assert message in err.message
    assert hint in err.hint
    if column is not None:
        assert err.column == column
    assert text in str(err) or not text


def test_leading_spaces_keep_columns_of_the_original_text():
    with pytest.raises(ExprError) as info:
        compile_expr("   frnt < 2", names={"front"})
    assert info.value.column == 4


def test_without_a_name_list_any_name_is_read_from_the_values():
    expr = compile_expr("anything + 1")
    assert expr({"anything": 1}) == 2
    with pytest.raises(KeyError):
        expr({})


def test_text_and_numbers_do_not_mix_at_compile_time():
    with pytest.raises(ExprError, match="do not fit together"):
        compile_expr('"a" < 3')


def test_yaml_numbers_and_booleans_are_accepted_as_values():
    assert compile_expr(0.5)() == 0.5
    assert compile_expr(True)() is True


def test_it_never_calls_eval(monkeypatch):
    import builtins

    def forbidden(*args, **kwargs):
        raise AssertionError("eval/exec must not be used")

    monkeypatch.setattr(builtins, "eval", forbidden)
    monkeypatch.setattr(builtins, "exec", forbidden)
    assert compile_expr("a * 2 > 3", names={"a"})({"a": 2}) is True


@pytest.mark.parametrize("text", ["\x00", "front < 20\x00", "x\x00 + 1"])
def test_a_nul_character_is_refused_with_its_column_on_every_python_311(text):
    with pytest.raises(ExprError, match="NUL character") as refused:
        compile_expr(text)
    assert refused.value.column == text.index("\x00") + 1


def test_an_expression_compiled_again_folds_the_constants_given_this_time():
    # the same text is compiled once and given again; constants equal in Python but not in
    # kind (True and 1, 0.0 and -0.0) are folded each their own way
    assert compile_expr("a * 2", constants={"a": 3})() == 6
    assert compile_expr("a * 2", constants={"a": 4})() == 8
    as_bool = compile_expr("a", constants={"a": True})()
    as_int = compile_expr("a", constants={"a": 1})()
    assert as_bool is True and type(as_int) is int
    assert str(compile_expr("a", constants={"a": -0.0})()) == "-0.0"
    assert str(compile_expr("a", constants={"a": 0.0})()) == "0.0"
    with pytest.raises(ExprError, match="unknown name"):
        compile_expr("a + b", names={"a"})  # the names it may read are part of it too
    assert compile_expr("a + b", names={"a", "b"})({"a": 1, "b": 2}) == 3


def test_the_table_of_compiled_expressions_holds_a_bounded_amount_of_text():
    from workbench.fsm import expr

    # a student's many long, different expressions (each edit of a parameter makes new ones)
    name = "a" * 300
    for n in range(1_000):  # some 300,000 characters in all
        assert compile_expr(f"{name} + {n}", constants={name: 1})() == 1 + n
    assert 0 < expr._compiled_chars <= expr.COMPILED_CHARS
    assert sum(len(key[0]) for key in expr._compiled) == expr._compiled_chars
