"""FSM files in YAML: read one into an :class:`~workbench.fsm.machine.FsmDefinition`.

The YAML is composed into a node tree (not loaded into plain Python objects) so every problem
can be reported as ``file:line:column`` with a hint. All problems of a file are reported at once.
See docs/fsm-format.md for the format.
"""

from __future__ import annotations

import difflib
import hashlib
import math
from collections.abc import Callable, Iterable
from dataclasses import replace
from pathlib import Path

import yaml
from yaml.constructor import SafeConstructor
from yaml.nodes import MappingNode, Node, ScalarNode, SequenceNode

from workbench.files.bounded import (
    FSM_LIMITS,
    BoundedFileError,
    check_text,
    compose_yaml,
    read_text,
)
from workbench.files.terminal import terminal_problem
from workbench.files.yamlread import (
    file_problem,
    problem_list,
    refused_problem,
    syntax_problem,
)
from workbench.fsm.machine import (
    PROFILES,
    Action,
    FsmDefinition,
    MotorAction,
    MoveAction,
    Parameter,
    ParameterError,
    Problem,
    SensorNeed,
    SetAction,
    State,
    StopAction,
    TimerAction,
    TransitionDef,
    TurnAction,
    Variable,
    WheelsAction,
    check_definition,
)

TOP_KEYS = ("name", "description", "sensors", "parameters", "variables", "initial", "states")
SENSOR_KEYS = ("kind", "mount", "port")
PARAMETER_KEYS = ("default", "min", "max", "description")
STATE_KEYS = ("description", "on_enter", "transitions")
TRANSITION_KEYS = ("when", "to", "set")
ACTIONS = ("wheels", "motor", "move", "turn", "stop", "set", "timer")
_KEY_HINTS = {
    "if": "when",
    "guard": "when",
    "condition": "when",
    "target": "to",
    "goto": "to",
    "next": "to",
    "actions": "on_enter",
    "enter": "on_enter",
    "entry": "on_enter",
    "initial_state": "initial",
    "start": "initial",
}

_INT = "tag:yaml.org,2002:int"
_FLOAT = "tag:yaml.org,2002:float"
_BOOL = "tag:yaml.org,2002:bool"
_NULL = "tag:yaml.org,2002:null"
_STR = "tag:yaml.org,2002:str"


class FsmFileError(ValueError):
    """An FSM file that cannot be used; ``problems`` lists every problem found (a long list
    is cut after :data:`~workbench.files.bounded.MAX_PROBLEMS`, saying how many more)."""

    def __init__(self, problems: list[Problem]) -> None:
        self.problems = problem_list(problems)
        super().__init__("\n".join(str(p) for p in self.problems))

    @classmethod
    def refused(cls, exc: BoundedFileError) -> FsmFileError:
        """The error of a file refused by the bounded reader."""
        return cls([refused_problem(exc)])


def load_fsm(path: str | Path) -> FsmDefinition:
    """Read an FSM file, or raise :class:`FsmFileError`."""
    path = Path(path)
    try:
        text = read_text(path, FSM_LIMITS)
    except BoundedFileError as exc:
        raise FsmFileError.refused(exc) from None
    return loads_fsm(text, str(path))


def loads_fsm(text: str, filename: str = "<text>") -> FsmDefinition:
    """Read FSM YAML from a string; ``filename`` is used in messages and as the default name."""
    try:
        root = compose_yaml(check_text(text, filename, FSM_LIMITS), filename, FSM_LIMITS)
    except BoundedFileError as exc:
        raise FsmFileError.refused(exc) from None
    except yaml.YAMLError as exc:
        raise FsmFileError([syntax_problem(filename, exc)]) from None
    if root is None:
        raise FsmFileError(
            [file_problem(filename, 1, 1, "the file is empty", "start with name: and states:")]
        )
    if not isinstance(root, MappingNode):
        mark = root.start_mark
        message = "an FSM file must be a mapping with name:, initial: and states:"
        raise FsmFileError([file_problem(filename, mark.line + 1, mark.column + 1, message)])
    reader = _Reader(filename)
    definition = reader.definition(root)
    for problem in check_definition(definition):
        if not reader.already_reported(problem.path):
            reader.report_problem(problem)
    if reader.problems:
        reader.problems.sort(key=lambda p: (p.line, p.column))
        raise FsmFileError(reader.problems)
    return replace(definition, digest=hashlib.sha256(text.encode("utf-8")).hexdigest())


def parse_param_overrides(definition: FsmDefinition, items: Iterable[str]) -> dict[str, float]:
    """``["front_blocked=40", ...]`` -> ``{"front_blocked": 40.0}``, checked against the
    definition's parameters; raises :class:`ParameterError` listing every bad item."""
    known = {p.name: p for p in definition.parameters}
    values: dict[str, float] = {}
    errors: list[str] = []
    for item in items:
        name, sep, raw = item.partition("=")
        name, raw = name.strip(), raw.strip()
        if not sep or not name:
            example = f"{next(iter(known), 'NAME')}=VALUE"
            errors.append(f"parameter {item!r} must be written NAME=VALUE, e.g. {example}")
            continue
        if name not in known:
            close = difflib.get_close_matches(name, list(known), n=1)
            hint = f"did you mean {close[0]!r}?" if close else _known(known)
            errors.append(f"{definition.name} has no parameter {name!r} ({hint})")
            continue
        try:
            value = float(raw)
        except ValueError:
            errors.append(f"parameter {name}: {raw!r} is not a number")
            continue
        if not math.isfinite(value):
            errors.append(f"parameter {name}: {raw!r} is not a finite number")
            continue
        p = known[name]
        if p.minimum is not None and value < p.minimum:
            errors.append(f"parameter {name}={raw} is below its minimum {p.minimum:g}")
        elif p.maximum is not None and value > p.maximum:
            errors.append(f"parameter {name}={raw} is above its maximum {p.maximum:g}")
        else:
            values[name] = value
    if errors:
        raise ParameterError("\n".join(errors))
    return values


def _known(known: Iterable[str]) -> str:
    names = ", ".join(known)
    return f"parameters: {names}" if names else "it has no parameters"


class _Reader:
    """Turns a YAML node tree into a definition, recording problems with their marks."""

    def __init__(self, filename: str) -> None:
        self.filename = filename
        self.problems: list[Problem] = []
        self.nodes: dict[tuple, Node] = {}
        self.reported: set[tuple] = set()
        self.constructor = SafeConstructor()

    # -- reporting ------------------------------------------------------------------------

    def report(self, node: Node, message: str, hint: str = "", path: tuple = ()) -> None:
        mark = node.start_mark
        self.problems.append(
            file_problem(self.filename, mark.line + 1, mark.column + 1, message, hint)
        )
        if path:
            self.reported.add(path)

    def already_reported(self, path: tuple) -> bool:
        return any(path[:n] in self.reported for n in range(1, len(path) + 1))

    def report_problem(self, problem: Problem) -> None:
        path = problem.path
        node = None
        for n in range(len(path), 0, -1):
            node = self.nodes.get(path[:n])
            if node is not None:
                break
        node = node or self.nodes[()]
        line, col = node.start_mark.line + 1, node.start_mark.column + 1
        if (
            problem.column
            and isinstance(node, ScalarNode)
            and node.style in (None, "'", '"')
            and node.start_mark.line == node.end_mark.line
        ):
            col += problem.column - 1 + (1 if node.style else 0)
        self.problems.append(file_problem(self.filename, line, col, problem.message, problem.hint))

    # -- typed access ---------------------------------------------------------------------

    def pairs(
        self, node: Node, path: tuple, what: str, keys: tuple[str, ...] | None = None
    ) -> list[tuple[str, Node, Node]]:
        """The (key, key node, value node) pairs of a mapping; problems for anything else."""
        if isinstance(node, ScalarNode) and node.tag == _NULL:
            return []
        if not isinstance(node, MappingNode):
            self.report(node, f"{what} must be a mapping of 'key: value' lines", path=path)
            return []
        out: list[tuple[str, Node, Node]] = []
        seen: dict[str, Node] = {}
        for key_node, value_node in node.value:
            if not isinstance(key_node, ScalarNode):
                self.report(key_node, f"a key in {what} must be a plain name", path=path)
                continue
            key = key_node.value
            if key in seen:
                line = seen[key].start_mark.line + 1
                self.report(
                    key_node,
                    f"{key!r} appears twice in {what} (first on line {line})",
                    "remove or rename one",
                    path=(*path, key),
                )
                continue
            seen[key] = key_node
            if keys is not None and key not in keys:
                self.report(key_node, f"unknown key {key!r} in {what}", _key_hint(key, keys))
                continue
            out.append((key, key_node, value_node))
        return out

    def items(self, node: Node, path: tuple, what: str, example: str) -> list[Node]:
        if isinstance(node, ScalarNode) and node.tag == _NULL:
            return []
        if not isinstance(node, SequenceNode):
            self.report(
                node, f"{what} must be a list of '- ...' items", f"e.g. {example}", path=path
            )
            return []
        return list(node.value)

    def text(self, node: Node, path: tuple, what: str) -> str | None:
        self.nodes[path] = node
        if not isinstance(node, ScalarNode) or node.tag == _NULL:
            self.report(node, f"{what} must be a single value", path=path)
            return None
        return node.value

    def number(self, node: Node, path: tuple, what: str) -> float | None:
        self.nodes[path] = node
        if isinstance(node, ScalarNode) and node.tag in (_INT, _FLOAT):
            value = float(self.constructor.construct_object(node))
            if math.isfinite(value):
                return value
        shown = node.value if isinstance(node, ScalarNode) else "a " + _kind(node)
        self.report(node, f"{what} must be a number, not {shown!r}", path=path)
        return None

    def expr(self, node: Node, path: tuple, what: str) -> str:
        self.nodes[path] = node
        if isinstance(node, ScalarNode):
            if node.tag == _BOOL:
                return "True" if self.constructor.construct_object(node) else "False"
            if node.tag == _NULL:
                self.report(node, f"{what} is empty", "write a value or a condition", path=path)
                return "0"
            if not node.tag.startswith("tag:yaml.org,2002:"):
                self.report(
                    node,
                    f"YAML read {node.tag!r} as a tag, not as part of {what}",
                    "write 'not x' instead of '!x', or quote the expression",
                    path=path,
                )
                return "0"
            return node.value
        self.report(
            node,
            f"{what} must be one expression, not a {_kind(node)}",
            "e.g. front < 50",
            path=path,
        )
        return "0"

    # -- the format ------------------------------------------------------------------------

    def definition(self, root: Node) -> FsmDefinition:
        self.nodes[()] = root
        fields = {key: (k, v) for key, k, v in self.pairs(root, ("@top",), "the file", TOP_KEYS)}
        for key, (k, _v) in fields.items():
            self.nodes[(key,)] = k
        name = Path(self.filename).stem
        if "name" in fields:
            given = self.text(fields["name"][1], ("name",), "name") or ""
            problem = terminal_problem(given, "the FSM's name")  # one line: no tab or newline
            if problem:
                self.report(fields["name"][1], problem, "write the name on one line", ("name",))
            name = given or name
        description = ""
        if "description" in fields:
            description = (
                self.text(fields["description"][1], ("description",), "description") or ""
            ).strip()
        sensors = self.sensors(fields["sensors"][1]) if "sensors" in fields else ()
        params = self.parameters(fields["parameters"][1]) if "parameters" in fields else ()
        variables = self.variables(fields["variables"][1]) if "variables" in fields else ()
        states: tuple[State, ...] = ()
        if "states" in fields:
            states = self.states(fields["states"][1])
        else:
            self.report(
                root, "no states: section", "add states: with at least one state", path=("states",)
            )
        initial = ""
        if "initial" in fields:
            initial = self.text(fields["initial"][1], ("initial",), "initial") or ""
        elif states:
            self.report(
                root, "no initial: state", f"add e.g. initial: {states[0].name}", path=("initial",)
            )
        return FsmDefinition(
            name=name,
            initial=initial,
            states=states,
            description=description,
            sensors=sensors,
            parameters=params,
            variables=variables,
            source=self.filename,
        )

    def sensors(self, node: Node) -> tuple[SensorNeed, ...]:
        out = []
        for name, key_node, value in self.pairs(node, ("sensors",), "sensors"):
            path = ("sensors", name)
            self.nodes[path] = key_node
            if not isinstance(value, MappingNode):
                self.report(
                    value,
                    f"sensor {name} must give kind:, mount: and port:",
                    _sensor_example(),
                    path=path,
                )
                out.append(SensorNeed(name, "", "", {p: 0 for p in PROFILES}))
                continue
            fields = dict(
                (k, v) for k, _kn, v in self.pairs(value, path, f"sensor {name}", SENSOR_KEYS)
            )
            for required in SENSOR_KEYS:
                if required not in fields:
                    self.report(
                        value,
                        f"sensor {name} has no {required}:",
                        _sensor_example(),
                        path=(*path, required),
                    )
            kind = self.text(fields["kind"], (*path, "kind"), "kind") if "kind" in fields else ""
            mount = (
                self.text(fields["mount"], (*path, "mount"), "mount") if "mount" in fields else ""
            )
            ports = self.ports(fields["port"], (*path, "port")) if "port" in fields else {}
            out.append(SensorNeed(name, kind or "", mount or "", ports))
        return tuple(out)

    def ports(self, node: Node, path: tuple) -> dict[str, int]:
        self.nodes[path] = node
        if isinstance(node, MappingNode):
            ports = {}
            for profile, k, v in self.pairs(node, path, "port"):
                self.nodes[(*path, profile, "@key")] = k
                number = self.number(v, (*path, profile), f"port ({profile})")
                if number is not None:
                    ports[profile] = int(number) if number.is_integer() else number
            return ports  # type: ignore[return-value]
        number = self.number(node, path, "port")
        if number is None:
            return {p: 0 for p in PROFILES}
        port = int(number) if number.is_integer() else number
        return {p: port for p in PROFILES}  # type: ignore[misc]

    def parameters(self, node: Node) -> tuple[Parameter, ...]:
        out = []
        for name, key_node, value in self.pairs(node, ("parameters",), "parameters"):
            path = ("parameters", name)
            self.nodes[path] = key_node
            if isinstance(value, ScalarNode):
                number = self.number(value, (*path, "default"), f"parameter {name}")
                defaults = {p: number for p in PROFILES} if number is not None else {}
                out.append(Parameter(name, defaults))
                continue
            fields = dict(
                (k, v) for k, _kn, v in self.pairs(value, path, f"parameter {name}", PARAMETER_KEYS)
            )
            defaults = {}
            if "default" not in fields:
                if isinstance(value, MappingNode):
                    self.report(
                        value,
                        f"parameter {name} has no default:",
                        "e.g. default: {unity: 0.9, web: 25, erobotic: 50}",
                        path=(*path, "default"),
                    )
            else:
                defaults = self.defaults(fields["default"], (*path, "default"), name)
            bounds = {}
            for key in ("min", "max"):
                if key in fields:
                    bounds[key] = self.number(fields[key], (*path, key), f"{key} of {name}")
            text = ""
            if "description" in fields:
                text = self.text(fields["description"], (*path, "description"), "description") or ""
            out.append(
                Parameter(
                    name, defaults, bounds.get("min"), bounds.get("max"), " ".join(text.split())
                )
            )
        return tuple(out)

    def defaults(self, node: Node, path: tuple, name: str) -> dict[str, float]:
        self.nodes[path] = node
        if isinstance(node, MappingNode):
            out = {}
            for profile, k, v in self.pairs(node, path, f"default of {name}"):
                self.nodes[(*path, profile, "@key")] = k
                number = self.number(v, (*path, profile), f"default of {name} ({profile})")
                if number is not None:
                    out[profile] = number
            return out
        number = self.number(node, path, f"default of {name}")
        return {p: number for p in PROFILES} if number is not None else {}

    def variables(self, node: Node) -> tuple[Variable, ...]:
        out = []
        for name, key_node, value in self.pairs(node, ("variables",), "variables"):
            self.nodes[("variables", name, "@key")] = key_node
            text = self.expr(value, ("variables", name), f"the initial value of {name}")
            out.append(Variable(name, text))
        return tuple(out)

    def states(self, node: Node) -> tuple[State, ...]:
        out = []
        for name, key_node, value in self.pairs(node, ("states",), "states"):
            path = ("states", name)
            self.nodes[path] = key_node
            fields = dict(
                (k, v) for k, _kn, v in self.pairs(value, path, f"state {name}", STATE_KEYS)
            )
            actions: list[Action] = []
            if "on_enter" in fields:
                items = self.items(
                    fields["on_enter"],
                    (*path, "on_enter"),
                    "on_enter",
                    "on_enter: [{move: 1.0}, {timer: 2}]",
                )
                for i, item in enumerate(items):
                    # a reported item keeps its place so later paths stay aligned
                    actions.append(self.action(item, (*path, "on_enter", i)) or StopAction())
            transitions = []
            if "transitions" in fields:
                items = self.items(
                    fields["transitions"],
                    (*path, "transitions"),
                    "transitions",
                    "transitions: [{when: front < 50, to: Turning}]",
                )
                for j, item in enumerate(items):
                    tr = self.transition(item, (*path, "transitions", j))
                    transitions.append(tr or TransitionDef(name))
            text = ""
            if "description" in fields:
                text = self.text(fields["description"], (*path, "description"), "description") or ""
            out.append(State(name, tuple(actions), tuple(transitions), " ".join(text.split())))
        return tuple(out)

    def action(self, node: Node, path: tuple) -> Action | None:
        self.nodes[path] = node
        if isinstance(node, ScalarNode):
            if node.value == "stop":
                return StopAction()
            self.report(node, f"unknown action {node.value!r}", _action_hint(node.value), path=path)
            return None
        if not isinstance(node, MappingNode) or len(node.value) != 1:
            many = isinstance(node, MappingNode) and len(node.value) > 1
            self.report(
                node,
                "put each action in its own list item"
                if many
                else "an action must be '- key: value' or '- stop'",
                "e.g. '- move: 1.0' then '- timer: 2' on the next line",
                path=path,
            )
            return None
        key_node, value = node.value[0]
        kind = key_node.value if isinstance(key_node, ScalarNode) else ""
        if kind not in ACTIONS:
            self.report(key_node, f"unknown action {kind!r}", _action_hint(kind), path=path)
            return None
        here = (*path, kind)
        if kind == "wheels":
            if not isinstance(value, SequenceNode) or len(value.value) != 2:
                self.report(
                    value,
                    "wheels takes two powers: [left, right]",
                    "e.g. wheels: [0.5, 0.5]",
                    path=path,
                )
                return None
            left, right = value.value
            return WheelsAction(
                self.expr(left, (*here, 0), "the left power"),
                self.expr(right, (*here, 1), "the right power"),
            )
        if kind == "motor":
            example = "e.g. motor: {wheel: left, power: 0.3}"
            if not isinstance(value, MappingNode):
                self.report(value, "motor takes a wheel and a power", example, path=path)
                return None
            fields = dict(
                (k, v) for k, _kn, v in self.pairs(value, here, "motor", ("wheel", "power"))
            )
            missing = [k for k in ("wheel", "power") if k not in fields]
            if missing:
                self.report(value, f"motor has no {' and no '.join(missing)}", example, path=path)
                return None
            wheel = self.text(fields["wheel"], (*here, "wheel"), "wheel") or "left"
            return MotorAction(wheel, self.expr(fields["power"], (*here, "power"), "power"))
        if kind == "stop":
            if not (isinstance(value, ScalarNode) and value.tag in (_NULL, _BOOL)):
                self.report(value, "stop takes no value", "write '- stop'", path=path)
                return None
            return StopAction()
        if kind == "set":
            return SetAction(self.assignments(value, here))
        text = self.expr(value, here, f"{kind}'s value")
        makers: dict[str, Callable[[str], Action]]
        makers = {"move": MoveAction, "turn": TurnAction, "timer": TimerAction}
        return makers[kind](text)

    def transition(self, node: Node, path: tuple) -> TransitionDef | None:
        self.nodes[path] = node
        if not isinstance(node, MappingNode):
            self.report(
                node,
                "a transition must be a mapping with to: (and usually when:)",
                "e.g. - {when: front < 50, to: Turning}",
                path=path,
            )
            return None
        fields = dict(
            (k, v) for k, _kn, v in self.pairs(node, path, "a transition", TRANSITION_KEYS)
        )
        if "to" not in fields:
            self.report(node, "this transition has no to: state", "add e.g. to: Forward", path=path)
            return None
        target = self.text(fields["to"], (*path, "to"), "to") or ""
        when = self.expr(fields["when"], (*path, "when"), "when") if "when" in fields else ""
        assigns = self.assignments(fields["set"], (*path, "set")) if "set" in fields else ()
        return TransitionDef(target, when, assigns)

    def assignments(self, node: Node, path: tuple) -> tuple[tuple[str, str], ...]:
        out = []
        for var, key_node, value in self.pairs(node, path, "set"):
            self.nodes[(*path, var, "@key")] = key_node
            out.append((var, self.expr(value, (*path, var), f"the value for {var}")))
        if isinstance(node, ScalarNode) and node.tag == _NULL:
            self.report(
                node, "set: has no assignments", "e.g. set: {RightDistance: front}", path=path
            )
        return tuple(out)


def _kind(node: Node) -> str:
    """ "scalar", "sequence" or "mapping": every node PyYAML composes is one of the three."""
    assert isinstance(node, ScalarNode | SequenceNode | MappingNode)
    return node.id


def _key_hint(key: str, keys: tuple[str, ...]) -> str:
    if key in _KEY_HINTS and _KEY_HINTS[key] in keys:
        return f"did you mean {_KEY_HINTS[key]!r}?"
    close = difflib.get_close_matches(key, keys, n=1)
    if close:
        return f"did you mean {close[0]!r}?"
    return "allowed here: " + ", ".join(keys)


def _action_hint(name: str) -> str:
    close = difflib.get_close_matches(name, ACTIONS, n=1)
    prefix = f"did you mean {close[0]!r}? " if close else ""
    return prefix + "actions: " + ", ".join(ACTIONS)


def _sensor_example() -> str:
    return "e.g. front: {kind: distance, mount: front, port: 2}"
