"""A loaded program made ready to run: every expression parsed, every name and key checked.

:func:`compile_program` adds to the loader's checks everything that needs the expression
language: each expression parses, reads only globals that exist and only parameters of its own
custom activity, keys are ones VIPLE knows, Code Activities are ones the workbench runs.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from . import kinds as K
from .code import CodeRefused, recognise
from .keys import KEY_NAMES
from .model import Activity, Program
from .problems import Problem, ProgramError, program_problem
from .viple_expr import ExprError, Expression, Value, literal, parse

#: a Variable's declared type -> the value an unset variable holds
DEFAULTS: dict[str, Value] = {
    "System.Int32": 0,
    "System.Double": 0.0,
    "System.String": "",
    "System.Boolean": False,
}


@dataclass
class Compiled:
    program: Program
    #: (activity id, value index) -> the parsed expression
    expressions: dict[tuple[int, int], Expression] = field(default_factory=dict)
    #: Data activity -> its constant
    constants: dict[int, Value] = field(default_factory=dict)
    #: lower-case global name -> (declared name, type)
    globals: dict[str, tuple[str, str]] = field(default_factory=dict)
    #: Key Press activity -> the key names it waits for
    key_sets: dict[int, frozenset[str]] = field(default_factory=dict)
    #: Custom Event activity -> the block (panel) name whose event pin it answers
    event_blocks: dict[int, str] = field(default_factory=dict)
    #: sensor activities: id -> (kind, port); port -1 for the raw sensor
    sensors: dict[int, tuple[int, int]] = field(default_factory=dict)

    def expr(self, activity: int, index: int) -> Expression:
        return self.expressions[(activity, index)]


def expression_indices(act: Activity, program: Program) -> list[int]:
    """Which of an activity's Values are expressions."""
    kind = act.kind
    if kind in (K.CALCULATE, K.WHILE):
        return [0]
    if kind in (K.IF, K.SWITCH):
        return list(range(len(act.values)))
    if kind == K.DRIVE:
        return [0, 1]
    if kind == K.BLOCK:
        return [i for i in range(1, len(act.values), 2) if act.values[i - 1].strip()]
    mapped = program.kinds.get(kind)
    if mapped is not None and mapped.value is not None and mapped.activity != "custom-event":
        return [mapped.value]
    return []


def compile_program(program: Program) -> Compiled:
    out = Compiled(program)
    problems: list[Problem] = []

    def problem(act: Activity, message: str, hint: str = "") -> None:
        problems.append(
            program_problem(
                program.source, message, hint, act.panel, act.id, act.kind, program.label(act)
            )
        )

    for var in program.globals:
        out.globals[var.name.lower()] = (var.name, var.type)
    assigned = {
        a.value(0).strip().lower() for a in program.activities.values() if a.kind == K.VARIABLE
    }
    for act in program.activities.values():
        kind = act.kind
        if kind == K.VARIABLE and not act.value(0).strip():
            problem(act, "the Variable names no variable", "choose one in its settings")
        if kind == K.VARIABLE and act.value(0).strip().lower() not in out.globals:
            out.globals[act.value(0).strip().lower()] = (act.value(0).strip(), "")
        if kind == K.DATA:
            out.constants[act.id] = literal(act.value(0))
        for index in expression_indices(act, program):
            text = act.value(index)
            try:
                expression = parse(text)
            except ExprError as exc:
                shown = text if len(text) <= 60 else text[:57] + "..."
                problem(act, f"Values[{index}] {shown!r}: {exc.message}" + _col(exc), exc.hint)
                continue
            out.expressions[(act.id, index)] = expression
            for name in sorted(expression.state_names - assigned - set(out.globals)):
                problem(
                    act,
                    f"Values[{index}] reads state.{name}, a global no Variable sets and the "
                    "program does not declare",
                    "declare it in VIPLE's Variables dialog, or check the spelling",
                )
            params = (
                {v.name.lower() for v in program.panels[act.panel].inputs}
                if act.panel != "Main"
                else set()
            )
            if kind == K.BLOCK:
                params = {v.name.lower() for v in program.panels[act.panel].inputs}
            for name in sorted(expression.instance_names - params):
                problem(
                    act,
                    f"Values[{index}] reads instance.{name}, which is not a parameter of "
                    f"{'the panel ' + act.panel if act.panel != 'Main' else 'Main'}",
                    "instance.X reads the parameters of the custom activity it is in",
                )
        if kind == K.KEY_PRESS:
            keys = []
            for text in act.values:
                key = KEY_NAMES.get(int(text)) if text.strip().isdigit() else None
                if key is None:
                    problem(
                        act,
                        f"key number {text.strip()[:10]!r} is not a key the workbench knows",
                        "choose a letter, digit, arrow or space in VIPLE",
                    )
                else:
                    keys.append(key)
            if not act.values:
                problem(act, "the Key Press Event has no key", "choose one in its settings")
            out.key_sets[act.id] = frozenset(keys)
        if kind == K.CODE:
            try:
                recognise(act.values)
            except CodeRefused as exc:
                problem(
                    act,
                    str(exc),
                    "write it as a form docs/viple-programs.md lists, or use Calculate activities",
                )
        if kind in (K.TOUCH, K.DISTANCE, K.OTHER_SENSOR):
            port = act.value(1).strip()
            if not port.lstrip("-").isdigit() or not 0 <= int(port) < 100:
                problem(act, f"the sensor port {port[:10]!r} is not 0 to 99", "choose a port")
            else:
                out.sensors[act.id] = (kind, int(port))
        if kind == K.RAW_SENSOR:
            out.sensors[act.id] = (kind, -1)
        mapped = program.kinds.get(kind)
        if mapped is not None and mapped.activity == "custom-event":
            choices = [act.value(mapped.value)] if mapped.value is not None else list(act.values)
            block = next((c.strip() for c in choices if c.strip() in program.panels), None)
            if block is None or block == "Main":
                problem(
                    act,
                    "the Custom Event names no custom activity of this program",
                    "choose the activity in its dropdown",
                )
            else:
                out.event_blocks[act.id] = block
    if problems:
        raise ProgramError(problems)
    return out


def _col(exc: ExprError) -> str:
    return f" (column {exc.column})" if exc.column is not None else ""
