"""Small, safe expressions for FSM guards and actions: ``front < 50 and not turn_done``.

An expression is parsed once with :func:`ast.parse` and only an allow-list of node types is
accepted: numbers, strings, True/False, names, ``+ - * /``, unary ``-``/``+``, comparisons
(chained too), ``and``/``or``/``not``, parentheses, and calls to ``abs``, ``min`` and ``max``.
It is turned into a tree of closures, so evaluating it is a few Python calls and never ``eval``.
"""

from __future__ import annotations

import ast
import difflib
import math
import operator
import warnings
from collections.abc import Callable, Collection, Mapping
from dataclasses import dataclass
from typing import cast

from workbench.files.bounded import digits_problem
from workbench.files.problems import ExprError

Value = float | int | bool | str
Env = Mapping[str, Value]
Fn = Callable[[Env], Value]

FUNCTIONS: dict[str, Callable[..., Value]] = {"abs": abs, "min": min, "max": max}
_ARITY = {"abs": (1, 1), "min": (2, None), "max": (2, None)}

_BINOPS = {ast.Add: operator.add, ast.Sub: operator.sub, ast.Mult: operator.mul}
_BINOPS[ast.Div] = operator.truediv
_CMPOPS = {
    ast.Lt: operator.lt,
    ast.LtE: operator.le,
    ast.Gt: operator.gt,
    ast.GtE: operator.ge,
    ast.Eq: operator.eq,
    ast.NotEq: operator.ne,
}
_REFUSED_OPS = {
    ast.Pow: ("**", "multiply instead, e.g. x * x"),
    ast.Mod: ("%", "only + - * / are available"),
    ast.FloorDiv: ("//", "use / (results are not rounded)"),
    ast.MatMult: ("@", "only + - * / are available"),
    ast.LShift: ("<<", "only + - * / are available"),
    ast.RShift: (">>", "only + - * / are available"),
    ast.BitAnd: ("&", "write 'and' for both conditions"),
    ast.BitOr: ("|", "write 'or' for either condition"),
    ast.BitXor: ("^", "only + - * / are available"),
    ast.In: ("in", "compare with == and combine with 'or'"),
    ast.NotIn: ("not in", "compare with != and combine with 'and'"),
    ast.Is: ("is", "use == to compare values"),
    ast.IsNot: ("is not", "use != to compare values"),
    ast.Invert: ("~", "use 'not' for a condition or '-' for a number"),
}
_REFUSED_NODES = {
    ast.Attribute: ("attribute access (x.y) is not allowed", "use plain names such as front"),
    ast.Subscript: ("indexing (x[...]) is not allowed", "use plain names such as front"),
    ast.Lambda: ("lambda is not allowed", "write the condition directly"),
    ast.IfExp: ("'x if c else y' is not allowed", "use two transitions with their own guards"),
    ast.NamedExpr: ("':=' is not allowed", "assign variables with a set: action"),
    ast.JoinedStr: ("f-strings are not allowed", "use a plain quoted string"),
    ast.List: ("lists are not allowed", "use single values"),
    ast.Tuple: ("tuples are not allowed", "use single values"),
    ast.Dict: ("dictionaries are not allowed", "use single values"),
    ast.Set: ("sets are not allowed", "use single values"),
    ast.Starred: ("'*' unpacking is not allowed", "pass the values one by one"),
}
_ALLOWED_SUMMARY = "numbers, names, + - * /, comparisons, and/or/not, abs() min() max()"

#: the longest expression, in characters
MAX_LENGTH = 2_000
#: the most levels of brackets, unary operators and operators inside each other
MAX_DEPTH = 50
#: the most values, names and operators (AST expression nodes) in one expression
MAX_TERMS = 200
_SIMPLER = "split it: keep parts in variables with a set: action"


@dataclass(frozen=True, eq=False)
class Expr:
    """A compiled expression: call it with a mapping of names to values."""

    text: str
    names: frozenset[str]
    evaluate: Fn
    constant: bool

    def __call__(self, env: Env | None = None) -> Value:
        return self.evaluate(env if env is not None else {})


#: expressions compiled so far, by their text, the names they may read and the constants folded
#: into them (a machine is built again for every run and every parameter edit, from the same
#: few texts); what a compiled expression holds grows with its text, so the table holds at most
#: COMPILED_CHARS characters of text, then starts afresh
_compiled: dict[tuple[str, frozenset[str] | None, tuple[tuple[str, str], ...]], Expr] = {}
_compiled_chars = 0
COMPILED_CHARS = 200_000


def compile_expr(
    text: str,
    names: Collection[str] | None = None,
    constants: Mapping[str, Value] | None = None,
) -> Expr:
    """Compile ``text``; ``names`` are the names it may read (None: any), ``constants`` are
    names whose values are fixed now and are folded into the result. An :class:`Expr` holds
    no state, so one compiled before for the same text, names and constants is given again."""
    if isinstance(text, bool):
        text = "True" if text else "False"
    elif isinstance(text, int | float):
        text = repr(text)
    if not isinstance(text, str):
        raise ExprError(f"an expression must be text, not {type(text).__name__}")
    # a constant goes into the key as written (True == 1 and 0.0 == -0.0, yet they fold apart)
    folded = tuple(sorted((k, repr(v)) for k, v in (constants or {}).items()))
    key = (text, None if names is None else frozenset(names), folded)
    found = _compiled.get(key)
    if found is None:
        global _compiled_chars
        found = _compile(text, names, constants)
        if _compiled_chars + len(text) > COMPILED_CHARS:
            _compiled.clear()
            _compiled_chars = 0
        _compiled[key] = found
        _compiled_chars += len(text)
    return found


def _compile(
    text: str, names: Collection[str] | None, constants: Mapping[str, Value] | None
) -> Expr:
    body = text.lstrip()
    lead = len(text) - len(body)
    if not body.strip():
        raise ExprError("empty expression", None, "write a value or a condition", text)
    _prescan(text, lead)
    try:
        with warnings.catch_warnings():
            # e.g. "1and x" or "\\.": Python's own warnings about the text are never printed
            warnings.simplefilter("ignore", SyntaxWarning)
            warnings.simplefilter("ignore", DeprecationWarning)
            tree = ast.parse(body, mode="eval")
    except SyntaxError as exc:
        col = (exc.offset or 1) + lead if (exc.lineno or 1) == 1 else exc.offset
        raise ExprError(f"bad syntax: {exc.msg}", col, _syntax_hint(body), text) from None
    except (RecursionError, MemoryError):
        raise ExprError("the expression is too complex to read", None, _SIMPLER, text) from None
    compiler = _Compiler(text, lead, names, constants or {})
    _check_size(compiler, tree.body)
    try:
        kind, payload = compiler.node(tree.body)
    except (RecursionError, MemoryError):
        raise ExprError("the expression is too complex to read", None, _SIMPLER, text) from None
    fn = _as_fn(kind, payload)
    return Expr(text, frozenset(compiler.read), fn, kind == "const")


def _prescan(text: str, lead: int) -> None:
    """Refuse, before :func:`ast.parse` recurses into it, an expression that is too long, nests
    brackets and unary operators too deeply, or writes a number with too many digits."""
    if len(text) > MAX_LENGTH:
        raise ExprError(
            f"the expression is {len(text):,} characters long; at most {MAX_LENGTH:,}",
            MAX_LENGTH + 1,
            _SIMPLER,
            text,
        )
    nul = text.find("\x00")
    if nul >= 0:
        # Python's parser refuses it too, with another error on some 3.11 releases
        raise ExprError("a NUL character (code 0)", nul + 1, "delete it and type the text", text)
    pending = [0]  # unary operators not yet closed, per open bracket
    operand_before = False
    i = lead
    while i < len(text):
        ch = text[i]
        start = i
        if ch in "'\"":
            i = _string_end(text, i)
            operand_before = True
            continue
        if ch.isdigit() or (ch == "." and text[i + 1 : i + 2].isdigit()):
            i = _number_end(text, i)
            reason = digits_problem(text[start:i])
            if reason is not None:
                raise ExprError(reason, start + 1, "write the value with fewer digits", text)
            operand_before = True
            continue
        if ch.isalpha() or ch == "_":
            while i < len(text) and (text[i].isalnum() or text[i] == "_"):
                i += 1
            word = text[start:i]
            if word == "not":
                pending[-1] += 1
                operand_before = False
            elif word in ("and", "or"):
                pending[-1] = 0
                operand_before = False
            else:
                operand_before = True
        elif ch in "([{":
            pending.append(0)
            operand_before = False
            i += 1
        elif ch in ")]}":
            if len(pending) > 1:
                pending.pop()
            operand_before = True
            i += 1
        elif ch in "-+~" and not operand_before:
            pending[-1] += 1
            i += 1
        else:
            if not ch.isspace():
                operand_before = False
                pending[-1] = 0
            i += 1
            continue
        if len(pending) - 1 + sum(pending) > MAX_DEPTH:
            raise ExprError(
                f"brackets and unary operators nest more than {MAX_DEPTH} deep",
                start + 1,
                _SIMPLER,
                text,
            )


def _string_end(text: str, i: int) -> int:
    """The index after the string literal that starts at ``text[i]`` (or the end of text)."""
    quote = text[i]
    i += 1
    while i < len(text) and text[i] != quote:
        i += 2 if text[i] == "\\" else 1
    return i + 1


def _number_end(text: str, i: int) -> int:
    """The index after the number literal that starts at ``text[i]``."""
    while i < len(text) and (text[i].isalnum() or text[i] in "._"):
        if text[i] in "eE" and text[i + 1 : i + 2] in ("+", "-"):
            i += 1
        i += 1
    return i


def _check_size(compiler: _Compiler, root: ast.expr) -> None:
    """Refuse a parsed expression with too many terms or nested too deeply (checked without
    recursion, before the compiler recurses into it)."""
    terms = sum(isinstance(node, ast.expr) for node in ast.walk(root))
    if terms > MAX_TERMS:
        raise compiler.fail(
            root,
            f"the expression has {terms:,} values and operators; at most {MAX_TERMS}",
            _SIMPLER,
        )
    stack = [(root, 1)]
    while stack:
        node, depth = stack.pop()
        if depth > MAX_DEPTH:
            raise compiler.fail(
                node,
                f"the expression nests more than {MAX_DEPTH} levels of operators, brackets "
                "and calls",
                _SIMPLER,
            )
        stack.extend(
            (child, depth + 1)
            for child in ast.iter_child_nodes(node)
            if isinstance(child, ast.expr)
        )


def _syntax_hint(text: str) -> str:
    if "&&" in text or "||" in text:
        return "write 'and' / 'or' instead of && / ||"
    if "!" in text.replace("!=", ""):
        return "write 'not x' instead of !x"
    stripped = text.replace("==", "").replace("!=", "").replace("<=", "").replace(">=", "")
    if "=" in stripped:
        return "compare with ==; assign variables with a set: action"
    if text.count("(") != text.count(")"):
        return "check that every '(' has its ')'"
    return f"expressions may use {_ALLOWED_SUMMARY}"


# A compiled node is ("const", value), ("name", name) or ("fn", closure).
_Node = tuple[str, object]


def _as_fn(kind: str, payload: object) -> Fn:
    # the kind says what the payload is: a Value, a name (str) or an Fn
    if kind == "const":
        value = cast(Value, payload)
        return lambda env: value
    if kind == "name":
        key = cast(str, payload)
        return lambda env: env[key]
    return cast(Fn, payload)


class _Compiler:
    def __init__(
        self,
        text: str,
        lead: int,
        names: Collection[str] | None,
        constants: Mapping[str, Value],
    ) -> None:
        self.text = text
        self.lead = lead
        self.names = names
        self.constants = constants
        self.read: set[str] = set()

    def fail(
        self, node: ast.AST, message: str, hint: str = "", after: ast.AST | None = None
    ) -> ExprError:
        """``after``: point at the operator that follows this operand instead of ``node``."""
        col = getattr(node, "col_offset", None)
        line = getattr(node, "lineno", 1)
        if after is not None and getattr(after, "end_lineno", 0) == 1:
            body = self.text[self.lead :]
            col = getattr(after, "end_col_offset", None) or 0
            while col < len(body) and body[col] in " \t()":
                col += 1
            line = 1
        if col is not None:
            col += 1 + (self.lead if line == 1 else 0)
        return ExprError(message, col, hint, self.text)

    def node(self, node: ast.AST) -> _Node:
        method = getattr(self, "_" + type(node).__name__, None)
        if method is not None:
            return method(node)
        if type(node) in _REFUSED_NODES:
            message, hint = _REFUSED_NODES[type(node)]
            raise self.fail(node, message, hint)
        raise self.fail(
            node,
            f"{type(node).__name__} expressions are not allowed",
            f"expressions may use {_ALLOWED_SUMMARY}",
        )

    def _Constant(self, node: ast.Constant) -> _Node:
        value = node.value
        if isinstance(value, float) and not math.isfinite(value):
            raise self.fail(node, "the number is too large (not finite)", "write a smaller number")
        if isinstance(value, bool | int | float | str):
            return ("const", value)
        raise self.fail(
            node, f"the value {value!r} is not allowed", "use numbers, strings, True or False"
        )

    def _Name(self, node: ast.Name) -> _Node:
        name = node.id
        if name in FUNCTIONS:
            raise self.fail(node, f"{name} is a function", f"call it, e.g. {name}(x)")
        self.read.add(name)
        if name in self.constants:
            return ("const", self.constants[name])
        if self.names is not None and name not in self.names:
            raise self.fail(node, f"unknown name {name!r}", _name_hint(name, self.names))
        return ("name", name)

    def _UnaryOp(self, node: ast.UnaryOp) -> _Node:
        if type(node.op) in _REFUSED_OPS:
            symbol, hint = _REFUSED_OPS[type(node.op)]
            raise self.fail(node, f"the operator {symbol} is not allowed", hint)
        unary: dict[type[ast.unaryop], Callable[..., Value]]
        unary = {ast.USub: operator.neg, ast.UAdd: operator.pos, ast.Not: operator.not_}
        op = unary[type(node.op)]
        kind, payload = self.node(node.operand)
        if kind == "const":
            return ("const", self.fold(node, op, payload))
        f = _as_fn(kind, payload)
        return ("fn", lambda env: op(f(env)))

    def _BinOp(self, node: ast.BinOp) -> _Node:
        op = _BINOPS.get(type(node.op))
        if op is None:
            symbol, hint = _REFUSED_OPS.get(type(node.op), ("?", ""))
            raise self.fail(node, f"the operator {symbol} is not allowed", hint, after=node.left)
        left, right = self.node(node.left), self.node(node.right)
        if op is operator.truediv and right[0] == "const" and right[1] == 0:
            raise self.fail(node, "division by zero", "check the divisor", after=node.left)
        if left[0] == "const" and right[0] == "const":
            return ("const", self.fold(node, op, left[1], right[1]))
        return ("fn", _binary(op, left, right))

    def _BoolOp(self, node: ast.BoolOp) -> _Node:
        parts = [self.node(v) for v in node.values]
        fns = [_as_fn(*p) for p in parts]
        if all(p[0] == "const" for p in parts):
            env: dict[str, Value] = {}
            if isinstance(node.op, ast.And):
                return ("const", _all_of(fns)(env))
            return ("const", _any_of(fns)(env))
        if isinstance(node.op, ast.And):
            return ("fn", _all_of(fns))
        return ("fn", _any_of(fns))

    def _Compare(self, node: ast.Compare) -> _Node:
        ops: list[Callable[[Value, Value], bool]] = []
        for i, op in enumerate(node.ops):
            if type(op) not in _CMPOPS:
                symbol, hint = _REFUSED_OPS.get(type(op), ("?", ""))
                before = node.left if i == 0 else node.comparators[i - 1]
                raise self.fail(
                    node, f"the comparison '{symbol}' is not allowed", hint, after=before
                )
            ops.append(_CMPOPS[type(op)])
        operands = [self.node(node.left)] + [self.node(c) for c in node.comparators]
        if all(p[0] == "const" for p in operands):
            fn = _chain(ops, [_as_fn(*p) for p in operands])
            return ("const", self.fold(node, fn, {}))
        if len(ops) == 1:
            return ("fn", _binary(ops[0], operands[0], operands[1]))
        return ("fn", _chain(ops, [_as_fn(*p) for p in operands]))

    def _Call(self, node: ast.Call) -> _Node:
        func = node.func
        if not isinstance(func, ast.Name):
            raise self.fail(
                node,
                "only the functions abs, min and max can be called",
                "attribute access and method calls are not allowed",
            )
        if func.id not in FUNCTIONS:
            raise self.fail(
                node,
                f"unknown function {func.id!r}",
                "only abs(x), min(a, b, ...) and max(a, b, ...) can be called",
            )
        if node.keywords:
            raise self.fail(node, f"{func.id}() takes no keyword arguments", "pass values only")
        low, high = _ARITY[func.id]
        count = len(node.args)
        if count < low or (high is not None and count > high):
            wanted = "exactly 1 argument" if low == high else f"at least {low} arguments"
            example = f"{func.id}(x)" if low == high else f"{func.id}(a, b)"
            raise self.fail(node, f"{func.id}() takes {wanted}, not {count}", f"e.g. {example}")
        parts = [self.node(a) for a in node.args]
        impl = FUNCTIONS[func.id]
        if all(p[0] == "const" for p in parts):
            return ("const", self.fold(node, impl, *(p[1] for p in parts)))
        fns = [_as_fn(*p) for p in parts]
        if len(fns) == 1:
            (f,) = fns
            return ("fn", lambda env: impl(f(env)))
        return ("fn", lambda env: impl(*[f(env) for f in fns]))

    def fold(self, node: ast.AST, fn: Callable[..., Value], *args: object) -> Value:
        try:
            value = fn(*args)
        except ZeroDivisionError:
            raise self.fail(node, "division by zero", "check the divisor") from None
        except TypeError as exc:
            raise self.fail(node, f"values do not fit together: {exc}", "") from None
        except OverflowError:
            value = math.inf
        if isinstance(value, float) and not math.isfinite(value):
            raise self.fail(node, "the result is too large (not finite)", "use smaller numbers")
        return value


def _binary(op: Callable[[Value, Value], Value], left: _Node, right: _Node) -> Fn:
    lk, lp = left
    rk, rp = right
    # as in _as_fn, a "name" payload is a str and a "const" payload a Value
    if lk == "name" and rk == "const":
        lname, rvalue = cast(str, lp), cast(Value, rp)
        return lambda env: op(env[lname], rvalue)
    if lk == "const" and rk == "name":
        lvalue, rname = cast(Value, lp), cast(str, rp)
        return lambda env: op(lvalue, env[rname])
    if lk == "name" and rk == "name":
        lname, rname = cast(str, lp), cast(str, rp)
        return lambda env: op(env[lname], env[rname])
    lf, rf = _as_fn(lk, lp), _as_fn(rk, rp)
    return lambda env: op(lf(env), rf(env))


def _chain(ops: list[Callable[[Value, Value], bool]], fns: list[Fn]) -> Fn:
    first = fns[0]
    pairs = list(zip(ops, fns[1:], strict=True))

    def chained(env: Env) -> bool:
        left = first(env)
        for op, f in pairs:
            right = f(env)
            if not op(left, right):
                return False
            left = right
        return True

    return chained


def _all_of(fns: list[Fn]) -> Fn:
    if len(fns) == 2:
        a, b = fns
        return lambda env: a(env) and b(env)

    def all_of(env: Env) -> Value:
        value: Value = True
        for f in fns:
            value = f(env)
            if not value:
                return value
        return value

    return all_of


def _any_of(fns: list[Fn]) -> Fn:
    if len(fns) == 2:
        a, b = fns
        return lambda env: a(env) or b(env)

    def any_of(env: Env) -> Value:
        value: Value = False
        for f in fns:
            value = f(env)
            if value:
                return value
        return value

    return any_of


def _name_hint(name: str, known: Collection[str]) -> str:
    if name in ("true", "false"):
        return f"write {name.capitalize()}"
    if name in ("null", "none", "None"):
        return "there is no empty value; use 0 or False"
    close = difflib.get_close_matches(name, list(known), n=1)
    if close:
        return f"did you mean {close[0]!r}?"
    if known:
        shown = sorted(known)
        listing = ", ".join(shown[:12]) + (", ..." if len(shown) > 12 else "")
        return f"known names: {listing}"
    return "no names are defined here"
