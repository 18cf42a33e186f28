"""VIPLE's expression language: the Dynamic LINQ grammar VIPLE ships, parsed and run here.

Precedence, lowest first: ``c ? a : b``; ``||`` ``or``; ``&&`` ``and``; ``=`` ``==`` ``!=``
``<>`` ``<`` ``<=`` ``>`` ``>=``; ``+`` ``-`` ``&`` (``+`` with a string, and ``&``, join
text); ``*`` ``/`` ``%`` ``mod``; unary ``-`` ``!`` ``not``; then literals (``12``, ``0.5``,
``"text"``, ``'c'``, ``true``, ``false``, ``null``), ``( )``, ``iif(c, a, b)``, ``value`` (also
``it``: the incoming message), ``state.X`` (a global variable), ``instance.X`` (a parameter of
the custom activity running), a bare name (a part of a Join's message), and ``Math.Abs``,
``Math.Min``, ``Math.Max``, ``Math.Round``, ``Math.Floor``, ``Math.Ceiling``, ``Math.Sqrt``,
``Math.Pow``, ``Convert.ToInt32``, ``Convert.ToDouble``, ``Convert.ToString``.

Keywords and member names are case-insensitive. Numbers follow C#: whole numbers stay whole
(``7 / 2`` is 3, truncated toward zero; ``7 % -2`` is 1), a whole number with a real gives a
real. Text compares by value. Nothing here calls ``eval``: the text is tokenized and parsed
into a tree of small functions, and sizes are bounded before parsing.
"""

from __future__ import annotations

import math
import operator
import re
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Any

from workbench.files.bounded import digits_problem
from workbench.files.problems import ExprError

MAX_LENGTH = 2_000
MAX_TOKENS = 400
MAX_DEPTH = 40
#: the longest text an expression may build (concatenation)
MAX_TEXT = 100_000
#: whole numbers stay within 64 bits, real ones finite (C#'s Int64 and Double)
INT_LIMIT = 1 << 63
#: a Join's message: Joins inside Joins at most this deep, and at most this many parts when
#: written out (a text counts one part for each TEXT_PART characters)
MAX_MESSAGE_DEPTH = 32
MAX_MESSAGE_PARTS = 20_000
TEXT_PART = 100

Value = Any


class LimitError(ExprError):
    """A value past the bounds every program keeps to (a number's range, a text's length, a
    Join message's size): a program that meets one is stopped, not only the flow."""


@dataclass(slots=True)
class Scope:
    """What an expression reads: the message, the globals, the block's parameters, a Join's
    named parts. Dictionaries are keyed by lower-case name."""

    value: Value = None
    state: Mapping[str, Value] = field(default_factory=dict)
    instance: Mapping[str, Value] = field(default_factory=dict)
    parts: Mapping[str, Value] | None = None


Fn = Callable[[Scope], Value]


class JoinMessage(dict):
    """A Join's message: its inputs' values by name, with how deep Joins nest in it and how
    many parts it has written out (a message holding another twice counts it twice)."""

    __slots__ = ("depth", "parts")

    depth: int
    parts: int


def parts_of(value: Value) -> int:
    """How many parts ``value`` has written out (see :data:`MAX_MESSAGE_PARTS`)."""
    if isinstance(value, JoinMessage):
        return value.parts
    if isinstance(value, str):
        return 1 + len(value) // TEXT_PART
    return 1


def join_message(parts: dict[str, Value]) -> JoinMessage:
    """The message a Join sends; :class:`LimitError` when it would nest too deep or grow too
    large (a loop that feeds the Join's message back into it)."""
    message = JoinMessage(parts)
    message.depth = 1 + max(
        (v.depth for v in parts.values() if isinstance(v, JoinMessage)), default=0
    )
    message.parts = 1 + sum(parts_of(v) for v in parts.values())
    if message.depth > MAX_MESSAGE_DEPTH:
        raise LimitError(
            f"its message would hold Joins {message.depth} deep (at most {MAX_MESSAGE_DEPTH}): "
            "does a loop bring the Join's own message back into it?"
        )
    if message.parts > MAX_MESSAGE_PARTS:
        raise LimitError(
            f"its message would have {message.parts:,} parts written out (at most "
            f"{MAX_MESSAGE_PARTS:,}): does a loop bring the Join's own message back into it?"
        )
    return message


def bounded(value: Value, col: int | None = None) -> Value:
    """``value`` when it is a number within range (or not a number); else an ExprError."""
    if isinstance(value, bool):
        return value
    if isinstance(value, int):
        if not -INT_LIMIT <= value < INT_LIMIT:
            raise LimitError(
                "the number grew past the range of a 64-bit whole number",
                col,
                "does a loop keep adding or multiplying it?",
            )
    elif isinstance(value, float) and not math.isfinite(value):
        raise LimitError(
            "the number grew past the range of a Double",
            col,
            "does a loop keep adding or multiplying it?",
        )
    return value


@dataclass(frozen=True, slots=True)
class Node:
    """One part of a parsed expression, for code that runs it without its functions
    (``fused.py``): ``fn`` runs it; ``kind`` says what it is, ``args`` its parts and ``data``
    what its function was made with. Kinds: ``literal`` (data: the value), ``value``,
    ``state`` (data: the lower-case key), ``compare`` (data: the operator, the function for
    values of any types, and the types that compare as Python compares them when the right
    side is a literal, else None), ``either`` (``||`` or ``&&``; data: the column, the
    operator and the answer a left side equal to it decides), ``not`` (data: the column),
    and ``other``: anything else, run only by its function."""

    kind: str
    fn: Fn
    args: tuple[Node, ...] = ()
    data: tuple[Any, ...] = ()


@dataclass(frozen=True)
class Expression:
    text: str
    run: Fn
    #: lower-case names read as state.X, instance.X and bare names
    state_names: frozenset[str]
    instance_names: frozenset[str]
    bare_names: frozenset[str]
    #: the parts of the expression (see Node)
    tree: Node | None = None

    def __call__(self, scope: Scope) -> Value:
        return self.run(scope)


# -- values as C# shows them -------------------------------------------------------------------


def show(value: Value, limit: int = MAX_TEXT) -> str:
    """A value as VIPLE prints it (C# ``ToString``): 1.0 is "1", true is "True". A Join's
    message is written out without recursion and cut after ``limit`` characters (``...``)."""
    if not isinstance(value, dict):
        return _show_one(value)
    out = ["{"]
    size = 1
    stack = [iter(value.items())]
    first = True
    while stack:
        item = next(stack[-1], None)
        if item is None:
            stack.pop()
            out.append("}")
            size += 1
            first = False
            continue
        key, part = item
        piece = f"{'' if first else ', '}{key} = "
        if isinstance(part, dict):
            piece += "{"
            stack.append(iter(part.items()))
            first = True
        else:
            piece += _show_one(part)
            first = False
        out.append(piece)
        size += len(piece)
        if size > limit:
            return "".join(out)[:limit] + "..."
    return "".join(out)


def _show_one(value: Value) -> str:
    if value is None:
        return ""
    if isinstance(value, bool):
        return "True" if value else "False"
    if isinstance(value, float):
        return show_double(value)
    return str(value)


#: the significant digits .NET Framework's ``Double.ToString()`` writes (its "G" format)
DOUBLE_DIGITS = 15
#: a double is written in fixed point when its decimal exponent (after rounding to
#: DOUBLE_DIGITS digits) lies in this range, else as ``1.5E+21`` / ``1E-05``
_FIXED_EXPONENTS = range(-4, DOUBLE_DIGITS)
_NOT_FINITE = {math.inf: "Infinity", -math.inf: "-Infinity"}


def show_double(x: float) -> str:
    """A double as VIPLE (a .NET Framework program) writes it with ``ToString()``: rounded to
    15 significant digits, trailing zeros dropped, no point for a whole number (``0.1 + 0.2``
    is ``0.3``, ``2.0`` is ``2``); fixed point when the decimal exponent is from -4 to 14,
    otherwise ``d.dddE+XX`` with a sign and at least two exponent digits (``1E+21``,
    ``1.5E-07``). Zero of either sign is ``0``; ``NaN``, ``Infinity``, ``-Infinity``."""
    if math.isnan(x):
        return "NaN"
    if math.isinf(x):
        return _NOT_FINITE[x]
    if x == 0:
        return "0"
    sign = "-" if x < 0 else ""
    mantissa, _, exp = f"{abs(x):.{DOUBLE_DIGITS - 1}e}".partition("e")
    digits = mantissa.replace(".", "").rstrip("0")
    e = int(exp)
    if e in _FIXED_EXPONENTS:
        if e >= 0:
            whole, frac = digits[: e + 1].ljust(e + 1, "0"), digits[e + 1 :]
        else:
            whole, frac = "0", "0" * (-e - 1) + digits
        return sign + whole + ("." + frac if frac else "")
    frac = "." + digits[1:] if len(digits) > 1 else ""
    return f"{sign}{digits[0]}{frac}E{'+' if e >= 0 else '-'}{abs(e):02d}"


def type_name(value: Value) -> str:
    if value is None:
        return "null"
    if isinstance(value, bool):
        return "Boolean"
    if isinstance(value, int):
        return "Int32"
    if isinstance(value, float):
        return "Double"
    if isinstance(value, str):
        return "String"
    return "Join message"


def _number(v: Value) -> bool:
    return isinstance(v, int | float) and not isinstance(v, bool)


# -- tokens ----------------------------------------------------------------------------------

_TOKEN = re.compile(
    r"""
    (?P<space>\s+)
  | (?P<number>\d+(?:\.\d+)?(?:[eE][+-]?\d+)?[dDfFmM]?)
  | (?P<string>"(?:[^"\\]|\\.|"")*")
  | (?P<char>'(?:[^'\\]|\\.|'')*')
  | (?P<name>[A-Za-z_][A-Za-z_0-9]*)
  | (?P<op>\|\||&&|==|!=|<>|<=|>=|[-+*/%<>=!?:(),.&|])
    """,
    re.VERBOSE,
)


@dataclass(frozen=True)
class _Tok:
    kind: str
    text: str
    col: int


def tokenize(text: str) -> list[_Tok]:
    out: list[_Tok] = []
    pos = 0
    while pos < len(text):
        m = _TOKEN.match(text, pos)
        if m is None:
            raise ExprError(
                f"the character {text[pos]!r} has no meaning here",
                pos + 1,
                'expressions use numbers, "text", names and operators',
            )
        kind = m.lastgroup or ""
        if kind != "space":
            if len(out) >= MAX_TOKENS:
                raise ExprError(
                    f"more than {MAX_TOKENS} parts", pos + 1, "split the work over Calculates"
                )
            out.append(_Tok(kind, m.group(), pos + 1))
        pos = m.end()
    out.append(_Tok("end", "", len(text) + 1))
    return out


# -- parser ----------------------------------------------------------------------------------

_KEYWORD_OPS = {"and": "&&", "or": "||", "not": "!", "mod": "%"}
_COMPARE = ("==", "=", "!=", "<>", "<", "<=", ">", ">=")


class _Parser:
    def __init__(self, text: str) -> None:
        self.toks = tokenize(text)
        self.i = 0
        self.depth = 0
        self.state: set[str] = set()
        self.instance: set[str] = set()
        self.bare: set[str] = set()
        #: id of a function made here -> what it is (its Node keeps the function, so no id
        #: is reused while parsing)
        self.nodes: dict[int, Node] = {}

    def node(self, fn: Fn) -> Node:
        """What the function ``fn`` made here is (``other`` when it was not noted)."""
        return self.nodes.get(id(fn)) or Node("other", fn)

    def noted(self, kind: str, fn: Fn, args: tuple[Fn, ...] = (), data: tuple = ()) -> Fn:
        self.nodes[id(fn)] = Node(kind, fn, tuple(self.node(a) for a in args), data)
        return fn

    def literal(self, value: Value) -> Fn:
        return self.noted("literal", _const(value), (), (value,))

    def literal_value(self, fn: Fn) -> tuple[Value] | None:
        """(the value,) when ``fn`` is a literal's function."""
        node = self.nodes.get(id(fn))
        return node.data if node is not None and node.kind == "literal" else None

    def negated(self, inner: Fn, col: int) -> Fn:
        """``-inner``: a literal itself where ``inner`` is a number's literal (``-0.2``, as
        programs write negative powers), so a comparison with it, and a fused chain, take it as
        the constant it is; anything else, and a literal whose negation is an error (``-"a"``),
        negated as it runs, which raises that error every time."""
        fn = _negate(inner, col)
        constant = self.literal_value(inner)
        if constant is not None and _number(constant[0]):
            try:
                value = fn(Scope())
            except ExprError:
                return fn
            return self.literal(value)
        return fn

    @property
    def tok(self) -> _Tok:
        return self.toks[self.i]

    def op(self) -> str:
        tok = self.tok
        if tok.kind == "op":
            return tok.text
        if tok.kind == "name":
            return _KEYWORD_OPS.get(tok.text.lower(), "")
        return ""

    def expect(self, text: str) -> _Tok:
        tok = self.tok
        if tok.kind == "op" and tok.text == text:
            self.i += 1
            return tok
        found = f"{tok.text!r}" if tok.kind != "end" else "the end"
        raise ExprError(f"expected {text!r} but found {found}", tok.col)

    def deeper(self) -> None:
        self.depth += 1
        if self.depth > MAX_DEPTH:
            raise ExprError(
                f"nested more than {MAX_DEPTH} deep", self.tok.col, "split the expression"
            )

    def parse(self) -> Fn:
        fn = self.conditional()
        if self.tok.kind != "end":
            raise ExprError(
                f"unexpected {self.tok.text!r}", self.tok.col, "is an operator missing?"
            )
        return fn

    def conditional(self) -> Fn:
        self.deeper()
        col = self.tok.col
        cond = self.logical_or()
        if self.op() == "?":
            self.i += 1
            yes = self.conditional()
            self.expect(":")
            no = self.conditional()
            cond = _choose(cond, yes, no, col)
        self.depth -= 1
        return cond

    def logical_or(self) -> Fn:
        left = self.logical_and()
        while self.op() == "||":
            col = self.tok.col
            self.i += 1
            right = self.logical_and()
            left = self.noted("either", _or(left, right, col), (left, right), (col, "||", True))
        return left

    def logical_and(self) -> Fn:
        left = self.comparison()
        while self.op() == "&&":
            col = self.tok.col
            self.i += 1
            right = self.comparison()
            left = self.noted("either", _and(left, right, col), (left, right), (col, "&&", False))
        return left

    def comparison(self) -> Fn:
        left = self.additive()
        while self.op() in _COMPARE:
            tok = self.tok
            self.i += 1
            right = self.additive()
            constant = self.literal_value(right)
            fn = _compare(tok.text, left, right, tok.col, constant)
            plain = _PLAIN.get(type(constant[0])) if constant is not None else None
            slow = _compare_values(tok.text, tok.col)
            left = self.noted("compare", fn, (left, right), (tok.text, slow, plain))
        return left

    def additive(self) -> Fn:
        left = self.multiplicative()
        while self.op() in ("+", "-", "&"):
            tok = self.tok
            self.i += 1
            left = _arith(tok.text, left, self.multiplicative(), tok.col)
        return left

    def multiplicative(self) -> Fn:
        left = self.unary()
        while self.op() in ("*", "/", "%"):
            op, col = self.op(), self.tok.col
            self.i += 1
            left = _arith(op, left, self.unary(), col)
        return left

    def unary(self) -> Fn:
        op = self.op()
        if op in ("-", "!"):
            col = self.tok.col
            self.i += 1
            self.deeper()
            inner = self.unary()
            self.depth -= 1
            if op == "-":
                return self.negated(inner, col)
            return self.noted("not", _not(inner, col), (inner,), (col,))
        return self.primary()

    def primary(self) -> Fn:
        tok = self.tok
        if tok.kind == "number":
            self.i += 1
            return self.literal(_number_literal(tok))
        if tok.kind in ("string", "char"):
            self.i += 1
            return self.literal(_string_literal(tok.text))
        if tok.kind == "op" and tok.text == "(":
            self.i += 1
            inner = self.conditional()
            self.expect(")")
            return inner
        if tok.kind == "name":
            return self.name()
        found = repr(tok.text) if tok.kind != "end" else "the end"
        raise ExprError(f"expected a value but found {found}", tok.col)

    def name(self) -> Fn:
        tok = self.tok
        word = tok.text.lower()
        self.i += 1
        if word in ("true", "false"):
            return self.literal(word == "true")
        if word == "null":
            return self.literal(None)
        if word in ("value", "it"):
            return self.noted("value", _value)
        if word == "iif":
            args = self.arguments(tok, 3)
            return _choose(args[0], args[1], args[2], tok.col)
        if word in ("state", "instance", "math", "convert") and self.op() == ".":
            self.i += 1
            member = self.tok
            if member.kind != "name":
                raise ExprError(f"expected a name after '{tok.text}.'", member.col)
            self.i += 1
            key = member.text.lower()
            if word == "state":
                self.state.add(key)
                return self.noted("state", _state(key, member.text, member.col), (), (key,))
            if word == "instance":
                self.instance.add(key)
                return _instance(key, member.text, member.col)
            return self.call(word, member)
        if word in _KEYWORD_OPS:
            raise ExprError(f"{tok.text!r} needs a value before it", tok.col)
        self.bare.add(word)
        return _part(word, tok.text, tok.col)

    def arguments(self, tok: _Tok, count: int | None) -> list[Fn]:
        self.expect("(")
        args: list[Fn] = []
        if not (self.tok.kind == "op" and self.tok.text == ")"):
            args.append(self.conditional())
            while self.tok.kind == "op" and self.tok.text == ",":
                self.i += 1
                args.append(self.conditional())
        self.expect(")")
        if count is not None and len(args) != count:
            raise ExprError(f"{tok.text} takes {count} values, not {len(args)}", tok.col)
        return args

    def call(self, owner: str, member: _Tok) -> Fn:
        key = f"{owner}.{member.text.lower()}"
        if key not in _FUNCTIONS:
            known = ", ".join(sorted(k for k in _FUNCTIONS if k.startswith(owner)))
            raise ExprError(f"unknown function {member.text!r}", member.col, f"known: {known}")
        fn, arity = _FUNCTIONS[key]
        args = self.arguments(member, arity)
        return _call(fn, args, member.text, member.col)


def parse(text: str) -> Expression:
    """Parse ``text``; an :class:`ExprError` says what and at which column."""
    if not isinstance(text, str):
        raise ExprError("an expression must be text")
    if len(text) > MAX_LENGTH:
        raise ExprError(
            f"the expression is {len(text):,} characters; at most {MAX_LENGTH:,}",
            None,
            "split it over several Calculates",
        )
    if not text.strip():
        raise ExprError("the expression is empty", 1, "write a value, e.g. value or 0")
    parser = _Parser(text)
    run = parser.parse()
    return Expression(
        text,
        run,
        frozenset(parser.state),
        frozenset(parser.instance),
        frozenset(parser.bare),
        parser.node(run),
    )


# -- literals --------------------------------------------------------------------------------


def _number_literal(tok: _Tok) -> int | float:
    text = tok.text.rstrip("dDfFmM")
    problem = digits_problem(text)
    if problem is not None:
        raise ExprError(problem, tok.col, "write a shorter number")
    if "." in text or "e" in text.lower() or text != tok.text:
        value = float(text)
        if not math.isfinite(value):
            raise ExprError("the number is too large", tok.col)
        return value
    return int(text)


_ESCAPES = {"n": "\n", "t": "\t", "r": "\r", "\\": "\\", '"': '"', "'": "'", "0": "\0"}


def _string_literal(text: str) -> str:
    quote, body = text[0], text[1:-1]
    body = body.replace(quote * 2, quote)
    return re.sub(r"\\(.)", lambda m: _ESCAPES.get(m.group(1), m.group(1)), body)


# -- the tree of functions -------------------------------------------------------------------


def _const(v: Value) -> Fn:
    return lambda s: v


def _value(s: Scope) -> Value:
    return s.value


def _state(key: str, name: str, col: int) -> Fn:
    def read(s: Scope) -> Value:
        try:
            return s.state[key]
        except KeyError:
            raise ExprError(
                f"there is no global variable {name!r}",
                col,
                "declare it in VIPLE's Variables dialog",
            ) from None

    return read


def _instance(key: str, name: str, col: int) -> Fn:
    def read(s: Scope) -> Value:
        try:
            return s.instance[key]
        except KeyError:
            raise ExprError(
                f"instance.{name} is not a parameter of the running activity", col
            ) from None

    return read


def _part(key: str, name: str, col: int) -> Fn:
    def read(s: Scope) -> Value:
        if s.parts is not None and key in s.parts:
            return s.parts[key]
        raise ExprError(
            f"unknown name {name!r}",
            col,
            "write value, state.NAME or instance.NAME, or a name given to a Join input",
        )

    return read


def want_bool(v: Value, col: int, op: str) -> bool:
    if not isinstance(v, bool):
        raise ExprError(f"{op} needs true or false, not {type_name(v)} {show(v)[:30]!r}", col)
    return v


def _choose(c: Fn, a: Fn, b: Fn, col: int) -> Fn:
    return lambda s: a(s) if want_bool(c(s), col, "the condition") else b(s)


def _or(a: Fn, b: Fn, col: int) -> Fn:
    return _either(a, b, col, "||", True)


def _and(a: Fn, b: Fn, col: int) -> Fn:
    return _either(a, b, col, "&&", False)


def _either(a: Fn, b: Fn, col: int, op: str, decides: bool) -> Fn:
    """``a op b`` for || (``decides`` True: a true left side is the answer) and && (False):
    both sides must be true or false, and the right one runs only when the left does not
    decide. The checks of true and false are written out, as the conditions of a program's
    Ifs run at every sensor report."""
    goes_on = not decides

    def run(s: Scope) -> Value:
        v = a(s)
        if v is goes_on:
            w = b(s)
            return w if w is True or w is False else want_bool(w, col, op)
        return decides if v is decides else want_bool(v, col, op)

    return run


def _not(a: Fn, col: int) -> Fn:
    return lambda s: not want_bool(a(s), col, "!")


def _negate(a: Fn, col: int) -> Fn:
    def run(s: Scope) -> Value:
        v = a(s)
        if not _number(v):
            raise ExprError(f"- needs a number, not {type_name(v)}", col)
        return bounded(-v, col)

    return run


#: a comparison of two numbers, or of two texts, as Python makes it
_TESTS: dict[str, Callable[[Any, Any], bool]] = {
    "==": operator.eq,
    "=": operator.eq,
    "!=": operator.ne,
    "<>": operator.ne,
    "<": operator.lt,
    "<=": operator.le,
    ">": operator.gt,
    ">=": operator.ge,
}


#: the types that compare as Python compares them, by the type of a literal they meet
_PLAIN = {str: (str,), int: (int, float), float: (int, float)}


def _compare(op: str, a: Fn, b: Fn, col: int, constant: tuple[Value] | None = None) -> Fn:
    """``a op b``; ``constant`` holds b's value when b is a literal (it is not run then)."""
    test = _TESTS[op]
    slow = _compare_values(op, col)
    # Two numbers (not true or false), or two texts, compare as Python compares them; any
    # other pair (and a subclass of a number or text) takes the general path, which checks
    # the types and words the errors. Most conditions compare something with a literal, whose
    # type is known when it is parsed.
    plain = _PLAIN.get(type(constant[0])) if constant is not None else None
    if constant is not None and plain is not None:
        y = constant[0]

        def with_literal(s: Scope) -> Value:
            x = a(s)
            return test(x, y) if type(x) in plain else slow(x, y)

        return with_literal

    def run(s: Scope) -> Value:
        x = a(s)
        y = b(s)
        kx, ky = type(x), type(y)
        if ((kx is float or kx is int) and (ky is float or ky is int)) or kx is ky is str:
            return test(x, y)
        return slow(x, y)

    return run


def _compare_values(op: str, col: int) -> Callable[[Value, Value], Value]:
    """``x op y`` for values of any types: the types checked, as C# compares them."""
    equality = op in ("==", "=", "!=", "<>")
    negate = op in ("!=", "<>")

    def run(x: Value, y: Value) -> Value:
        if _number(x) and _number(y):
            pass
        elif equality and (x is None or y is None or type(x) is type(y)):
            return (x == y) != negate
        elif not (isinstance(x, str) and isinstance(y, str)):
            raise ExprError(
                f"{op} cannot compare {type_name(x)} with {type_name(y)}",
                col,
                "convert one side, e.g. Convert.ToDouble(value)",
            )
        if equality:
            return (x == y) != negate
        if op == "<":
            return x < y
        if op == "<=":
            return x <= y
        if op == ">":
            return x > y
        return x >= y

    return run


def _arith(op: str, a: Fn, b: Fn, col: int) -> Fn:
    def run(s: Scope) -> Value:
        x, y = a(s), b(s)
        if op == "&" or (op == "+" and (isinstance(x, str) or isinstance(y, str))):
            text = show(x) + show(y)
            if len(text) > MAX_TEXT:
                raise LimitError(f"the text grew past {MAX_TEXT:,} characters", col)
            return text
        if not (_number(x) and _number(y)):
            raise ExprError(f"{op} needs numbers, not {type_name(x)} and {type_name(y)}", col)
        if op == "+":
            return bounded(x + y, col)
        if op == "-":
            return bounded(x - y, col)
        if op == "*":
            return bounded(x * y, col)
        if y == 0:
            raise ExprError("division by zero", col, "check the divisor before dividing")
        if isinstance(x, int) and isinstance(y, int):
            quotient = abs(x) // abs(y) * (1 if (x >= 0) == (y >= 0) else -1)
            return quotient if op == "/" else x - quotient * y
        return bounded(x / y if op == "/" else math.fmod(x, y), col)

    return run


def _call(fn: Callable[..., Value], args: list[Fn], name: str, col: int) -> Fn:
    def run(s: Scope) -> Value:
        values = [arg(s) for arg in args]
        try:
            result = fn(*values)
        except (TypeError, ValueError, OverflowError) as exc:
            raise ExprError(f"{name}: {exc}", col) from None
        return bounded(result, col)

    return run


def _num_arg(v: Value) -> float | int:
    if not _number(v):
        raise ValueError(f"needs a number, not {type_name(v)}")
    return v


def _round(v: Value, digits: Value = 0) -> float:
    return float(round(_num_arg(v), int(_num_arg(digits))))


def _to_int(v: Value) -> int:
    if isinstance(v, str):
        text = v.strip()
        if len(text) > 30:
            raise ValueError(f"{v[:30]!r}... is not a whole number of at most 30 digits")
        try:
            return int(text)
        except ValueError:
            raise ValueError(f"{v[:30]!r} is not a whole number") from None
    if isinstance(v, bool):
        return int(v)
    return round(_num_arg(v))


def _to_double(v: Value) -> float:
    if isinstance(v, str):
        try:
            result = float(v.strip())
        except ValueError:
            raise ValueError(f"{v[:30]!r} is not a number") from None
        if not math.isfinite(result):
            raise ValueError("not a finite number")
        return result
    if isinstance(v, bool):
        return float(v)
    return float(_num_arg(v))


def _sqrt(v: Value) -> float:
    x = _num_arg(v)
    if x < 0:
        raise ValueError("the square root of a negative number")
    return math.sqrt(x)


def _pow(a: Value, b: Value) -> float:
    result = math.pow(_num_arg(a), _num_arg(b))
    if not math.isfinite(result):
        raise ValueError("the result is too large")
    return result


_FUNCTIONS: dict[str, tuple[Callable[..., Value], int | None]] = {
    "math.abs": (lambda v: abs(_num_arg(v)), 1),
    "math.min": (lambda a, b: min(_num_arg(a), _num_arg(b)), 2),
    "math.max": (lambda a, b: max(_num_arg(a), _num_arg(b)), 2),
    "math.round": (_round, None),
    "math.floor": (lambda v: float(math.floor(_num_arg(v))), 1),
    "math.ceiling": (lambda v: float(math.ceil(_num_arg(v))), 1),
    "math.sqrt": (_sqrt, 1),
    "math.pow": (_pow, 2),
    "convert.toint32": (_to_int, 1),
    "convert.todouble": (_to_double, 1),
    "convert.tostring": (show, 1),
}


def literal(text: str) -> Value:
    """A Data activity's value: a number, true/false, a quoted string's content, else the
    raw text (VIPLE 3.x saved text without quotes)."""
    body = text.strip()
    if re.fullmatch(r"-?\d{1,18}", body):
        return int(body)
    if re.fullmatch(r"-?\d{1,30}\.\d{1,30}([eE][+-]?\d{1,3})?|-?\d{1,30}[eE][+-]?\d{1,3}", body):
        value = float(body)
        return value if math.isfinite(value) else text
    if body.lower() in ("true", "false"):
        return body.lower() == "true"
    if len(body) >= 2 and body[0] == body[-1] and body[0] in "\"'":
        return _string_literal(body)
    return text
