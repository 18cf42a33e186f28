"""FSM definitions: the dataclasses, their checks, parameter values and sensor binding.

A definition (usually loaded from YAML by :mod:`workbench.fsm.yaml_file`) names the sensors it
reads, tunable parameters with per-profile defaults, variables, and states; the engine in
:mod:`workbench.fsm.machine` runs it. Import these names from ``workbench.fsm.machine``.
"""

from __future__ import annotations

import difflib
import keyword
from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass, field

from workbench.files.problems import Problem
from workbench.fsm.expr import FUNCTIONS, ExprError, Value, compile_expr
from workbench.sim.sensor_kinds import KINDS, sensor_kind
from workbench.sim.sensors import MOUNTS, PORT_RANGE, SensorSpec

PROFILES = ("unity", "web", "erobotic")
EVENTS = ("turn_done", "timer_done")
RESERVED = frozenset(EVENTS) | frozenset(FUNCTIONS) | {"True", "False", "None"}


class FsmError(ValueError):
    """Base class of every FSM problem; the message says what to change."""


class ParameterError(FsmError):
    """Parameter values that cannot be used (unknown name, not a number, out of range)."""


class FsmRuntimeError(FsmError):
    """A guard or action failed while running (e.g. division by zero, text compared to a number)."""


class SensorBindingError(FsmError):
    """The robot lacks a sensor the FSM reads."""


def _at(
    path: tuple[str | int, ...], message: str, hint: str = "", column: int | None = None
) -> Problem:
    """A problem of a definition: ``path`` locates it, e.g. ("states", "Forward", "to"), and
    ``column`` (from 1), when given, is the column inside the value there."""
    return Problem(message, hint, path=path, column=column or 0)


class FsmDefinitionError(FsmError):
    """A definition with problems; ``problems`` lists every one of them."""

    def __init__(self, name: str, problems: list[Problem]) -> None:
        self.name = name
        self.problems = problems
        lines = "\n".join(f"  {p}" for p in problems)
        super().__init__(f"FSM {name!r} has {len(problems)} problem(s):\n{lines}")


# ----------------------------------------------------------------------------- definition


@dataclass(frozen=True)
class SensorNeed:
    """A sensor the FSM reads under ``name``: its kind, where it is mounted, its default port."""

    name: str
    kind: str
    mount: str
    ports: Mapping[str, int]

    def port_for(self, profile: str) -> int:
        return self.ports[profile]


@dataclass(frozen=True)
class Parameter:
    """A tunable number with a default per profile (``{"unity": 0.9, "web": 25, ...}``)."""

    name: str
    defaults: Mapping[str, float]
    minimum: float | None = None
    maximum: float | None = None
    description: str = ""


@dataclass(frozen=True)
class Variable:
    name: str
    initial: str


@dataclass(frozen=True)
class WheelsAction:
    left: str
    right: str


@dataclass(frozen=True)
class MotorAction:
    wheel: str
    power: str


@dataclass(frozen=True)
class MoveAction:
    power: str


@dataclass(frozen=True)
class TurnAction:
    degrees: str


@dataclass(frozen=True)
class StopAction:
    pass


@dataclass(frozen=True)
class SetAction:
    assignments: tuple[tuple[str, str], ...]


@dataclass(frozen=True)
class TimerAction:
    seconds: str


Action = WheelsAction | MotorAction | MoveAction | TurnAction | StopAction | SetAction | TimerAction


@dataclass(frozen=True)
class TransitionDef:
    """Go to ``target`` when ``when`` holds ("" = at the next tick), running ``set`` first."""

    target: str
    when: str = ""
    set: tuple[tuple[str, str], ...] = ()


@dataclass(frozen=True)
class State:
    name: str
    on_enter: tuple[Action, ...] = ()
    transitions: tuple[TransitionDef, ...] = ()
    description: str = ""


@dataclass(frozen=True)
class FsmDefinition:
    name: str
    initial: str
    states: tuple[State, ...]
    description: str = ""
    sensors: tuple[SensorNeed, ...] = ()
    parameters: tuple[Parameter, ...] = ()
    variables: tuple[Variable, ...] = ()
    source: str = ""
    #: sha256 of the file's text as it was read ("" when not read from a file)
    digest: str = field(default="", compare=False)

    def state(self, name: str) -> State:
        for s in self.states:
            if s.name == name:
                return s
        raise KeyError(name)

    def parameter(self, name: str) -> Parameter:
        for p in self.parameters:
            if p.name == name:
                return p
        raise KeyError(name)

    def runtime_names(self) -> set[str]:
        """The names guards and actions may read."""
        return (
            {s.name for s in self.sensors}
            | {p.name for p in self.parameters}
            | {v.name for v in self.variables}
            | set(EVENTS)
        )


@dataclass(frozen=True)
class Transition:
    """A transition that fired: when, from where to where, the guard, and the values it read."""

    time: float
    source: str
    target: str
    guard_text: str
    #: None for a name the guard did not get to read ("a or b" with a true)
    values: Mapping[str, Value | None]


# ----------------------------------------------------------------------------- checking


def check_definition(defn: FsmDefinition) -> list[Problem]:
    """Every problem of ``defn`` (names, states, expressions, ports, parameter ranges)."""
    problems: list[Problem] = []
    add = problems.append
    if not defn.states:
        add(_at(("states",), "no states are defined", "add at least one state"))
    names = [s.name for s in defn.states]
    for i, name in enumerate(names):
        if name in names[:i]:
            add(_at(("states", name), f"state {name!r} is defined twice", "rename one"))
    if defn.states and defn.initial not in names:
        add(
            _at(
                ("initial",),
                f"the initial state {defn.initial!r} is not defined"
                if defn.initial
                else "no initial state is given",
                _choices_hint(defn.initial, names, "states"),
            )
        )
    declared: dict[str, str] = {}
    for group, items in (
        ("sensors", defn.sensors),
        ("parameters", defn.parameters),
        ("variables", defn.variables),
    ):
        for item in items:
            _check_name(group, item.name, declared, add)
    _check_sensors(defn, add)
    _check_parameters(defn, add)
    params = {p.name for p in defn.parameters}
    seen_vars: set[str] = set()
    for var in defn.variables:
        _check_expr(("variables", var.name), var.initial, params | seen_vars, add)
        seen_vars.add(var.name)
    runtime = defn.runtime_names()
    variables = {v.name for v in defn.variables}
    for state in defn.states:
        base = ("states", state.name)
        for i, action in enumerate(state.on_enter):
            _check_action((*base, "on_enter", i), action, runtime, variables, add)
        for j, tr in enumerate(state.transitions):
            path = (*base, "transitions", j)
            if tr.target not in names:
                add(
                    _at(
                        (*path, "to"),
                        f"unknown state {tr.target!r} in to:",
                        _choices_hint(tr.target, names, "states"),
                    )
                )
            if tr.when:
                _check_expr((*path, "when"), tr.when, runtime, add)
            _check_assignments((*path, "set"), tr.set, runtime, variables, add)
    return problems


def _check_name(group: str, name: str, declared: dict[str, str], add: Callable) -> None:
    path = (group, name, "@key")
    if not name.isidentifier() or keyword.iskeyword(name):
        add(_at(path, f"{name!r} cannot be used as a name", "use letters, digits and _"))
    elif name in RESERVED:
        add(_at(path, f"{name!r} is reserved", "choose another name"))
    elif name in declared:
        add(_at(path, f"{name!r} is already declared under {declared[name]}", "rename one"))
    declared.setdefault(name, group)


def _check_sensors(defn: FsmDefinition, add: Callable) -> None:
    for s in defn.sensors:
        path = ("sensors", s.name)
        if s.kind not in KINDS:
            add(_at((*path, "kind"), f"unknown sensor kind {s.kind!r}", _one_of(KINDS)))
        if s.mount not in MOUNTS:
            add(_at((*path, "mount"), f"unknown mount {s.mount!r}", _one_of(MOUNTS)))
        elif s.kind in KINDS and s.mount not in sensor_kind(s.kind).mounts:
            allowed = sensor_kind(s.kind).mounts
            add(
                _at(
                    (*path, "mount"),
                    f"a {s.kind} sensor cannot be mounted {s.mount}",
                    _one_of(allowed),
                )
            )
        missing = [p for p in PROFILES if s.ports.get(p) is None]
        if missing:
            add(
                _at(
                    (*path, "port"),
                    f"no port for profile {', '.join(missing)}",
                    "give one port number, or one per profile",
                )
            )
        bad: dict[object, list[str]] = {}
        for profile in PROFILES:
            port = s.ports.get(profile)
            if port is not None and (
                isinstance(port, bool) or not isinstance(port, int) or port not in PORT_RANGE
            ):
                bad.setdefault(port, []).append(profile)
        for wrong, profiles in bad.items():
            add(
                _at(
                    (*path, "port", profiles[0]),
                    f"port {wrong!r} ({', '.join(profiles)}) is not a whole number from "
                    f"{PORT_RANGE.start} to {PORT_RANGE.stop - 1}",
                )
            )
        for profile in s.ports:
            if profile not in PROFILES:
                add(
                    _at(
                        (*path, "port", profile, "@key"),
                        f"unknown profile {profile!r}",
                        _one_of(PROFILES),
                    )
                )
    clashes: dict[tuple[str, int, str], list[str]] = {}
    for profile in PROFILES:
        owner: dict[int, str] = {}
        for s in defn.sensors:
            port = s.ports.get(profile)
            if port in owner:
                clashes.setdefault((s.name, port, owner[port]), []).append(profile)
            elif port is not None:
                owner[port] = s.name
    for (name, port, other), profiles in clashes.items():
        add(
            _at(
                ("sensors", name, "port"),
                f"port {port} ({', '.join(profiles)}) is also used by sensor {other!r}",
                "give each sensor its own port",
            )
        )


def _check_parameters(defn: FsmDefinition, add: Callable) -> None:
    for p in defn.parameters:
        path = ("parameters", p.name)
        lo, hi = p.minimum, p.maximum
        if lo is not None and hi is not None and lo > hi:
            add(_at((*path, "min"), f"min {lo:g} is above max {hi:g}", "swap them"))
        for profile, value in p.defaults.items():
            where = (*path, "default", profile)
            if profile not in PROFILES:
                add(_at((*where, "@key"), f"unknown profile {profile!r}", _one_of(PROFILES)))
            elif lo is not None and value < lo:
                add(_at(where, f"default {value:g} ({profile}) is below min {lo:g}"))
            elif hi is not None and value > hi:
                add(_at(where, f"default {value:g} ({profile}) is above max {hi:g}"))


def _check_action(
    path: tuple, action: Action, names: set[str], variables: set[str], add: Callable
) -> None:
    if isinstance(action, WheelsAction):
        _check_expr((*path, "wheels", 0), action.left, names, add)
        _check_expr((*path, "wheels", 1), action.right, names, add)
    elif isinstance(action, MotorAction):
        if action.wheel not in ("left", "right"):
            add(
                _at(
                    (*path, "motor", "wheel"),
                    f"unknown wheel {action.wheel!r}",
                    "use left or right",
                )
            )
        _check_expr((*path, "motor", "power"), action.power, names, add)
    elif isinstance(action, MoveAction):
        _check_expr((*path, "move"), action.power, names, add)
    elif isinstance(action, TurnAction):
        _check_expr((*path, "turn"), action.degrees, names, add)
    elif isinstance(action, TimerAction):
        _check_expr((*path, "timer"), action.seconds, names, add)
    elif isinstance(action, SetAction):
        _check_assignments((*path, "set"), action.assignments, names, variables, add)


def _check_assignments(
    path: tuple,
    pairs: Iterable[tuple[str, str]],
    names: set[str],
    variables: set[str],
    add: Callable,
) -> None:
    for var, text in pairs:
        if var not in variables:
            add(
                _at(
                    (*path, var, "@key"),
                    f"{var!r} is not a variable",
                    f"declare it under variables: ({var}: 0)"
                    if var not in names
                    else "only variables can be assigned; sensors, parameters and events cannot",
                )
            )
        _check_expr((*path, var), text, names, add)


def _check_expr(path: tuple, text: str, names: set[str], add: Callable) -> None:
    try:
        compile_expr(text, names)
    except ExprError as exc:
        add(_at(path, exc.message, exc.hint, exc.column))


def _one_of(options: Iterable[str]) -> str:
    return "use one of " + ", ".join(options)


def _choices_hint(name: str, options: list[str], what: str) -> str:
    close = difflib.get_close_matches(name or "", options, n=1)
    if close:
        return f"did you mean {close[0]!r}?"
    return f"{what}: {', '.join(options)}" if options else ""


# ----------------------------------------------------------------------------- parameters


def resolve_params(
    defn: FsmDefinition, profile: str, overrides: Mapping[str, float] | None = None
) -> dict[str, float]:
    """Profile defaults with ``overrides`` applied, or :class:`ParameterError` listing the
    unknown names, non-numbers, values out of range and missing defaults."""
    if profile not in PROFILES:
        raise ParameterError(f"unknown profile {profile!r}: {_one_of(PROFILES)}")
    overrides = dict(overrides or {})
    errors: list[str] = []
    known = [p.name for p in defn.parameters]
    for name in overrides:
        if name not in known:
            hint = _choices_hint(name, known, "parameters") or "it has no parameters"
            errors.append(f"{defn.name} has no parameter {name!r} ({hint})")
    values: dict[str, float] = {}
    for p in defn.parameters:
        if p.name in overrides:
            raw = overrides[p.name]
            if isinstance(raw, bool) or not isinstance(raw, int | float):
                errors.append(f"parameter {p.name}: {raw!r} is not a number")
                continue
            value = float(raw)
            if p.minimum is not None and value < p.minimum:
                errors.append(f"parameter {p.name}={value:g} is below its minimum {p.minimum:g}")
            elif p.maximum is not None and value > p.maximum:
                errors.append(f"parameter {p.name}={value:g} is above its maximum {p.maximum:g}")
            values[p.name] = value
        elif profile in p.defaults:
            values[p.name] = float(p.defaults[profile])
        else:
            errors.append(
                f"parameter {p.name} has no default for the {profile} profile: "
                f"set it, e.g. --param {p.name}=VALUE"
            )
    if errors:
        raise ParameterError("\n".join(errors))
    return values


# ----------------------------------------------------------------------------- sensors


def preset_sensors(defn: FsmDefinition, profile: str) -> list[SensorSpec]:
    """The sensors ``defn`` reads, on their default ports for ``profile``."""
    return [SensorSpec(s.kind, s.port_for(profile), s.mount) for s in defn.sensors]


def bind_sensors(defn: FsmDefinition, specs: Iterable[SensorSpec], profile: str) -> dict[str, int]:
    """Map each sensor name of ``defn`` to the port of a configured sensor of the same kind and
    mount (preferring the profile's default port), or raise :class:`SensorBindingError`."""
    specs = list(specs)
    taken: set[int] = set()
    binding: dict[str, int] = {}
    missing: list[SensorNeed] = []
    for need in defn.sensors:
        fits = [s for s in specs if s.kind == need.kind and s.mount == need.mount]
        fits = [s for s in fits if s.port not in taken]
        if not fits:
            missing.append(need)
            continue
        preferred = need.ports.get(profile)
        chosen = next((s for s in fits if s.port == preferred), fits[0])
        taken.add(chosen.port)
        binding[need.name] = chosen.port
    if missing:
        raise SensorBindingError(_missing_message(defn, missing, specs, profile))
    return binding


def _missing_message(
    defn: FsmDefinition, missing: list[SensorNeed], specs: list[SensorSpec], profile: str
) -> str:
    used = {s.port for s in specs}
    lines = []
    for need in missing:
        port = need.ports.get(profile)
        if port is None or port in used:
            port = next(p for p in range(1, PORT_RANGE.stop) if p not in used)
        used.add(port)
        example = SensorSpec(need.kind, port, need.mount)
        line = (
            f"{defn.name} needs a {need.kind} sensor mounted {need.mount} "
            f"(read as {need.name!r}): add one, e.g. --sensor {example}"
        )
        others = [s for s in specs if s.mount == need.mount and s.kind != need.kind]
        if others:
            line += f" (the {others[0].kind} sensor {others[0]} cannot stand in for it)"
        lines.append(line)
    have = ", ".join(str(s) for s in specs) or "none"
    return "\n".join(lines) + f"\nconfigured sensors: {have}"
