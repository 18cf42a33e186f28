"""Chains of a program's activities fused into single Python functions, made once at load.

A flow runs activity after activity; between two of them the interpreter's loop only counts
the activity and dispatches the next one. Where the next activity is known from the diagram
(the first link of the pin an activity sends on), that dispatch can be done once, here: a
*chain* is the straight-line code of the activities a flow runs from one *head* activity on,
an If's pins becoming branches of the code, until the flow ends, sleeps in a Timer, reaches an
activity that is not fused (a While, a Join, a block call...), comes back to an activity of its
own path (a loop), or has run as many activities as its slice has room for.

Every chain is a function ``chain(flow, room) -> int`` that runs at most ``room`` activities
and returns how many it ran, plus :data:`ENDED` when the flow ended, or :data:`SLEEPS` when it
sleeps in a Timer (``flow.wait`` seconds); otherwise the flow goes on at ``flow.activity``
with ``flow.value`` and ``flow.in_pin``. An error is raised as the activity's own step would
raise it, with ``flow.activity`` set to the activity that raised it and ``flow.ran`` to the
activities run, that one included.

Why it is the same program: each activity's code is the code of its prepared step in
``interp.py`` (the same calls, in the same order, on the same values), with the message kept
in a local variable instead of ``flow.value`` between two activities; a fan-out's other links
start their flows where the step's sender starts them; and the chain writes the flow's place
back wherever it stops. An expression is written out part by part (``viple_expr.Node``) with
the operations, the order and the checks of true and false of the part's function, and any
part that goes wrong (or that is not written out) is run by that function on the same
values, so its error has the same text. Where every value a call needs is known when the
chain is made (a Data's constant stored by a Variable, a Timer of a known wait, a Robot Drive
of two literal powers), the call is made then, once, and the code holds its result; a call
that raises is left in the code, to raise as the step does. So commands, prints, globals,
changes, flows, activity counts and errors are the step-by-step run's
(``ProgramController(fuse=False)``; ``tests/program/test_fused.py`` runs programs both ways).

Security: the source is made of this module's own text and of names it numbers itself
(``c0``, ``c1`` ...); every value that comes from the program (ids, pins, constants, names,
expressions) reaches the code as an argument of the function that makes the chain, never as
text. Sizes are bounded: :data:`MAX_CHAIN` activities a chain, :data:`MAX_NEST` Ifs nested in
one, :data:`MAX_FUSED` activities and :data:`MAX_LINES` lines for all the chains of a program
(past them, activities run step by step), :data:`MAX_PARTS` expression parts written out.
"""

from __future__ import annotations

import re
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field
from typing import Any

from .model import ELSE, Link
from .viple_expr import Node

#: a chain's result, past the count of activities it ran: the flow ended, or it sleeps
ENDED = 1 << 16
SLEEPS = 1 << 17
#: (a step run alone only: a While that found nothing changed) the flow waits for the next tick
PARKS = 1 << 18
#: the count of activities in a chain's result
COUNT = ENDED - 1
#: activities in one chain, Ifs nested in one, and activities fused for a whole program
MAX_CHAIN = 40
MAX_NEST = 8
MAX_FUSED = 2_000
#: parts of expressions written out as code for a whole program (past it, and below
#: MAX_PART_DEPTH parts inside parts, an expression part runs as its function)
MAX_PARTS = 2_000
MAX_PART_DEPTH = 16
#: lines of code for a whole program (a chain stops where its program's lines run out), so
#: making the chains of the largest program a file may hold takes a fraction of a second
MAX_LINES = 12_000
#: the Python operator of each comparison (this module's own text, looked up by the
#: operator's token)
_PY_OPS = {"==": "==", "=": "==", "!=": "!=", "<>": "!=", "<": "<", "<=": "<=", ">": ">",
           ">=": ">="}  # fmt: skip

Chain = Callable[[Any, int], int]


@dataclass(frozen=True)
class Fusable:
    """How one activity runs inside a chain: its ``kind`` of code (see :class:`_Writer`), the
    values that code needs, and the links of its output pins."""

    kind: str
    values: tuple[Any, ...] = ()
    #: output pin -> its links (the first continues the flow, the others start flows)
    pins: dict[int, tuple[Link, ...]] = field(default_factory=dict)


@dataclass
class _Source:
    """The text of one chain and the values it is made with (``c0``, ``c1`` ...)."""

    lines: list[str] = field(default_factory=list)
    cells: list[Any] = field(default_factory=list)
    #: (activity, activities run with it) for each place an error may come from
    places: list[tuple[int, int]] = field(default_factory=list)

    def cell(self, value: Any) -> str:
        self.cells.append(value)
        return f"c{len(self.cells) - 1}"

    def put(self, depth: int, text: str) -> None:
        self.lines.append("    " * depth + text)


#: the helpers every chain may call, by the names its code uses
HELPERS = (
    "ctl",
    "spawn",
    "command",
    "show",
    "convert",
    "truth",
    "check_timer",
    "power",
    "WheelPowers",
    "first_sensor_value",
    "through",
    "want_bool",
)


class _Writer:
    """Writes the chain of one head: activity by activity, an If's pins as branches."""

    def __init__(
        self,
        fusable: dict[int, Fusable],
        budget: int,
        parts: int,
        lines: int,
        helpers: dict[str, Any],
    ) -> None:
        self.fusable = fusable
        self.helpers = helpers
        self.budget = budget
        #: lines this chain may take
        self.lines = lines
        #: expression parts this chain may still write out
        self.parts = parts
        self.src = _Source()
        self.size = 0
        self.temps = 0
        #: the locals that hold true or false for certain (a comparison's, a ``!``'s, an
        #: ``&&``'s or ``||``'s value, whose functions give nothing else or raise): their
        #: checks of true and false are left out
        self.bools: set[str] = set()
        #: activities a chain stopped at for a reason of its own (they may head chains)
        self.stops: list[int] = []
        #: (the value,) where the code being written holds a message known when the chain is
        #: made (a Data's constant, a Variable's store of one), else None; see :meth:`folded`
        self.known: tuple[Any] | None = None

    def write(self, head: int) -> _Source:
        src = self.src
        src.put(1, "def chain(flow, room):")
        src.put(2, "v = flow.value")
        src.put(2, "try:")
        self.activity(head, 1, 3, 0, frozenset())
        src.put(2, "except BaseException:")
        src.put(3, "flow.activity, flow.ran = PLACES[at]")
        src.put(3, "raise")
        src.put(1, "return chain")
        # the flow's frame and the globals, read once, where the code uses them (every line
        # that may raise comes after an ``at = ...``, the first of the try's body)
        used = set(re.findall(r"\w+", "\n".join(src.lines)))
        prologue = [
            "        " + line
            for line, name in (("frame = flow.frame", "frame"), ("G = ctl.globals", "G"))
            if name in used
        ]
        src.lines[2:2] = prologue
        return src

    def stop(self, depth: int, target: int, pin: str, ran: int) -> None:
        """The flow goes on at ``target``, entering it at ``pin``, after ``ran`` activities."""
        src = self.src
        src.put(depth, f"flow.activity = {src.cell(target)}")
        src.put(depth, "flow.value = v")
        src.put(depth, f"flow.in_pin = {pin}")
        src.put(depth, f"return {ran}")

    def activity(self, aid: int, ran: int, depth: int, nest: int, path: frozenset[int]) -> None:
        """The code of activity ``aid``, the ``ran``-th of the chain, and of what follows."""
        src = self.src
        spec = self.fusable[aid]
        self.size += 1
        src.places.append((aid, ran))
        src.put(depth, f"at = {len(src.places) - 1}")
        path = path | {aid}
        code = getattr(self, "_" + spec.kind)
        code(spec, ran, depth, nest, path)

    def send(
        self, spec: Fusable, out: int, ran: int, depth: int, nest: int, path: frozenset[int]
    ) -> None:
        """``v`` out of pin ``out``: the other links start flows, the first goes on here."""
        src = self.src
        links = spec.pins.get(out, ())
        if not links:
            src.put(depth, f"return {ran | ENDED}")
            return
        for link in links[1:]:
            src.put(depth, f"spawn({src.cell(link.target)}, v, frame, {src.cell(link.in_pin)})")
        self.follow(links[0], ran, depth, nest, path)

    def follow(self, link: Link, ran: int, depth: int, nest: int, path: frozenset[int]) -> None:
        src = self.src
        pin = src.cell(link.in_pin)
        target = link.target
        if (
            target not in self.fusable
            or target in path
            or ran >= MAX_CHAIN
            or nest > MAX_NEST
            or self.size >= self.budget
            or len(self.src.lines) >= self.lines
        ):
            if target in self.fusable:
                self.stops.append(target)
            self.stop(depth, target, pin, ran)
            return
        src.put(depth, f"if room == {ran}:")
        self.stop(depth + 1, target, pin, ran)
        self.activity(target, ran + 1, depth, nest, path)

    # -- each kind's code: the same calls as its prepared step in interp.py ----------------
    def _pass(self, spec: Fusable, ran: int, depth: int, nest: int, path: frozenset[int]) -> None:
        self.send(spec, 0, ran, depth, nest, path)

    def _data(self, spec: Fusable, ran: int, depth: int, nest: int, path: frozenset[int]) -> None:
        self.src.put(depth, f"v = {self.src.cell(spec.values[0])}")
        self.known = (spec.values[0],)
        self.send(spec, 0, ran, depth, nest, path)

    def _variable(
        self, spec: Fusable, ran: int, depth: int, nest: int, path: frozenset[int]
    ) -> None:
        src = self.src
        key, vtype = spec.values
        # a known message stored is known too: its conversion is made here, once
        stored = self.folded(self.helpers["convert"], self.known[0], vtype) if self.known else None
        if stored is not None:
            src.put(depth, f"v = {src.cell(stored[0])}")
        else:
            src.put(depth, f"v = convert(v, {src.cell(vtype)})")
        self.known = stored
        src.put(depth, f"G[{src.cell(key)}] = v")
        src.put(depth, "ctl.changes += 1")
        self.send(spec, 0, ran, depth, nest, path)

    def folded(self, fn: Callable[..., Any], *args: Any) -> tuple[Any] | None:
        """(``fn(*args)``,) worked out now, for code whose values are all known when the chain
        is made, so that it does not run again at every pass; None where it raises (the code
        then runs it, and raises the same error, as the activity's own step does)."""
        try:
            return (fn(*args),)
        except Exception:
            return None

    # -- expressions: each part's value in a local of its own ------------------------------
    def temp(self) -> str:
        self.temps += 1
        return f"x{self.temps}"

    def expr(self, expression: Any, depth: int) -> str:
        """Code for the value of ``expression`` (an Expression); the local that holds it."""
        return self.part(expression.tree or Node("other", expression.run), depth, 0)

    def part(self, node: Node, depth: int, level: int) -> str:
        """Code for one part, its own parts first, as its function runs them: the same
        operations in the same order, the same checks of true and false; an error is raised
        by the part's own function, run on the same values, so it has the same text."""
        src = self.src
        kind = node.kind
        if (
            self.parts <= 0
            or level >= MAX_PART_DEPTH
            or (kind == "compare" and node.data[0] not in _PY_OPS)
        ):
            kind = "other"
        self.parts -= 1
        if kind == "literal":
            return src.cell(node.data[0])
        if kind == "value":
            return "v"
        out = self.temp()
        fn = src.cell(node.fn)
        if kind == "state":
            src.put(depth, "try:")
            src.put(depth + 1, f"{out} = G[{src.cell(node.data[0])}]")
            src.put(depth, "except KeyError:")
            src.put(depth + 1, f"{out} = through({fn}, v, G, frame)")
        elif kind == "compare":
            self._compare(node, out, depth, level)
            self.bools.add(out)
        elif kind == "either":
            self._either(node, out, depth, level)
            self.bools.add(out)
        elif kind == "not":
            inner = self.part(node.args[0], depth, level + 1)
            if inner in self.bools:
                src.put(depth, f"{out} = not {inner}")
            else:
                src.put(depth, f"if {inner} is True:")
                src.put(depth + 1, f"{out} = False")
                src.put(depth, f"elif {inner} is False:")
                src.put(depth + 1, f"{out} = True")
                src.put(depth, "else:")
                where = f"{src.cell(node.data[0])}, '!'"
                src.put(depth + 1, f"{out} = not want_bool({inner}, {where})")
            self.bools.add(out)
        else:
            src.put(depth, f"{out} = through({fn}, v, G, frame)")
        return out

    def _compare(self, node: Node, out: str, depth: int, level: int) -> None:
        """As viple_expr's ``_compare``: two numbers or two texts as Python compares them, any
        other pair by the function that checks the types; a literal right side is not run."""
        src = self.src
        op, slow, plain = node.data
        left, right = node.args
        x = self.part(left, depth, level + 1)
        test = f"{{}} {_PY_OPS[op]} {{}}"
        if plain is not None:
            y = src.cell(right.data[0])
            src.put(depth, f"if type({x}) in {src.cell(plain)}:")
        else:
            y = self.part(right, depth, level + 1)
            kx, ky = self.temp(), self.temp()
            src.put(depth, f"{kx} = type({x})")
            src.put(depth, f"{ky} = type({y})")
            src.put(depth, f"if (({kx} is float or {kx} is int) and ({ky} is float or {ky} is "
                           f"int)) or {kx} is {ky} is str:")  # fmt: skip
        src.put(depth + 1, f"{out} = " + test.format(x, y))
        src.put(depth, "else:")
        src.put(depth + 1, f"{out} = {src.cell(slow)}({x}, {y})")

    def _either(self, node: Node, out: str, depth: int, level: int) -> None:
        """As viple_expr's ``_either``: the right side runs only when the left one does not
        decide; both must be true or false."""
        src = self.src
        col, op, decides = node.data
        left, right = node.args
        where = f"{src.cell(col)}, {src.cell(op)}"
        x = self.part(left, depth, level + 1)
        known = x in self.bools
        src.put(
            depth, f"if {'not ' if decides else ''}{x}:" if known else f"if {x} is {not decides}:"
        )
        y = self.part(right, depth + 1, level + 1)
        if y in self.bools:
            src.put(depth + 1, f"{out} = {y}")
        else:
            src.put(depth + 1, f"if {y} is True or {y} is False:")
            src.put(depth + 2, f"{out} = {y}")
            src.put(depth + 1, "else:")
            src.put(depth + 2, f"{out} = want_bool({y}, {where})")
        if known:
            src.put(depth, "else:")
            src.put(depth + 1, f"{out} = {decides}")
            return
        src.put(depth, f"elif {x} is {decides}:")
        src.put(depth + 1, f"{out} = {decides}")
        src.put(depth, "else:")
        src.put(depth + 1, f"{out} = want_bool({x}, {where})")

    # -- the activities that run expressions ---------------------------------------------
    def _calculate(
        self, spec: Fusable, ran: int, depth: int, nest: int, path: frozenset[int]
    ) -> None:
        value = self.expr(spec.values[0], depth)
        self.src.put(depth, f"v = {value}")
        self.known = None
        self.send(spec, 0, ran, depth, nest, path)

    def _if(self, spec: Fusable, ran: int, depth: int, nest: int, path: frozenset[int]) -> None:
        src = self.src
        # each branch's code ends in a return; the code after it holds the message as it was
        known = self.known
        for index, condition in enumerate(spec.values):
            truth = self.expr(condition, depth)
            if truth in self.bools:  # true or false for certain: no check
                src.put(depth, f"if {truth}:")
                self.send(spec, index, ran, depth + 1, nest + 1, path)
                self.known = known
                continue
            src.put(depth, f"t = {truth}")
            src.put(depth, "if t is True:")
            self.send(spec, index, ran, depth + 1, nest + 1, path)
            self.known = known
            src.put(depth, "if t is not False:")
            src.put(depth + 1, f"truth(t, {index})")
        self.send(spec, ELSE, ran, depth, nest, path)

    def _timer(self, spec: Fusable, ran: int, depth: int, nest: int, path: frozenset[int]) -> None:
        src = self.src
        # a known number of milliseconds passes the check, and its wait is worked out, once
        known = self.known
        wait = self.folded(_wait, self.helpers["check_timer"], known[0]) if known else None
        if wait is None:
            src.put(depth, "check_timer(v)")
        links = spec.pins.get(0, ())
        if not links:
            src.put(depth, f"return {ran | ENDED}")
            return
        for link in links[1:]:
            src.put(depth, f"spawn({src.cell(link.target)}, v, frame, {src.cell(link.in_pin)})")
        first = links[0]
        src.put(depth, f"flow.activity = {src.cell(first.target)}")
        src.put(depth, "flow.value = v")
        src.put(depth, f"flow.in_pin = {src.cell(first.in_pin)}")
        if wait is None:
            src.put(depth, "flow.wait = max(0.0, float(v)) / 1000.0")
        else:
            src.put(depth, f"flow.wait = {src.cell(wait[0])}")
        src.put(depth, f"return {ran | SLEEPS}")

    def _drive(self, spec: Fusable, ran: int, depth: int, nest: int, path: frozenset[int]) -> None:
        src = self.src
        left, right = spec.values
        # two literal powers: the command is the same at every pass, made once (a command is
        # a frozen value, so one object may be sent any number of times)
        fixed = None
        if _literal(left) and _literal(right):
            fixed = self.folded(self._wheels, left.tree.data[0], right.tree.data[0])
        if fixed is not None:
            src.put(depth, f"command({src.cell(fixed[0])})")
        else:
            src.put(depth, f"left = power({self.expr(left, depth)}, 'left')")
            src.put(depth, f"right = power({self.expr(right, depth)}, 'right')")
            src.put(depth, "command(WheelPowers(left, right))")
        self.send(spec, 0, ran, depth, nest, path)

    def _wheels(self, left: Any, right: Any) -> Any:
        """The command the code below makes of these powers (raising as it would)."""
        power = self.helpers["power"]
        return self.helpers["WheelPowers"](power(left, "left"), power(right, "right"))

    def _print(self, spec: Fusable, ran: int, depth: int, nest: int, path: frozenset[int]) -> None:
        self.src.put(depth, "ctl._print(show(v))")
        self.send(spec, 0, ran, depth, nest, path)

    def _code(self, spec: Fusable, ran: int, depth: int, nest: int, path: frozenset[int]) -> None:
        self.src.put(depth, "v = first_sensor_value(v)")
        self.known = None
        self.send(spec, 0, ran, depth, nest, path)


def _literal(expression: Any) -> bool:
    """Whether an expression is a literal (its value in its tree's data)."""
    return expression.tree is not None and expression.tree.kind == "literal"


def _wait(check_timer: Callable[[Any], None], value: Any) -> float:
    """The seconds a Timer's code below waits for ``value``, its check first."""
    check_timer(value)
    return max(0.0, float(value)) / 1000.0


def fuse(
    fusable: dict[int, Fusable], heads: Iterable[int], helpers: dict[str, Any]
) -> dict[int, Chain]:
    """The chains of the activities in ``heads`` (and of those their chains stop at), while
    the program's budget of :data:`MAX_FUSED` fused activities lasts; ``helpers`` are the
    functions the code calls (:data:`HELPERS`)."""
    chains: dict[int, Chain] = {}
    todo = [h for h in heads if h in fusable]
    fused = 0
    parts = MAX_PARTS
    lines = MAX_LINES
    while todo and fused < MAX_FUSED and lines > 0:
        head = todo.pop(0)
        if head in chains:
            continue
        writer = _Writer(fusable, MAX_FUSED - fused, parts, lines, helpers)
        src = writer.write(head)
        fused += writer.size
        parts = max(0, writer.parts)
        lines -= len(src.lines)
        chains[head] = _make(src, helpers)
        todo.extend(writer.stops)
    return chains


def _make(src: _Source, helpers: dict[str, Any]) -> Chain:
    """The chain function of ``src``: its text compiled, its values given as arguments."""
    names = [*HELPERS, "PLACES", *(f"c{i}" for i in range(len(src.cells)))]
    text = f"def make({', '.join(names)}):\n" + "\n".join(src.lines) + "\n"
    builtins = {f.__name__: f for f in (max, float, int, str, type, BaseException, KeyError)}
    namespace: dict[str, Any] = {"__builtins__": builtins}
    exec(compile(text, "<viple chain>", "exec"), namespace)
    values = [helpers[name] for name in HELPERS]
    return namespace["make"](*values, tuple(src.places), *src.cells)
