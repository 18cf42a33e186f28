"""Which FSM that comes with the workbench a definition is, behaviour for behaviour.

A lab's "your program" objectives must rest on the student's own work, so a run by an FSM
that is one the workbench ships is not theirs, whatever the file is called. Two FSMs are the
same here when they behave the same: their states, actions, transitions, sensors, variables
and parameter ranges are equal once names, descriptions and the order of the parts that have
no order (sensors, parameters, variables, states other than the initial one) are set aside,
and the parameters in force have the same values. Names are set aside by naming things
afresh: the states in the order a run reaches them, and the sensors, parameters and variables
in the order the machine's expressions first read them (each expression is rewritten with the
new names, the way Python writes it back, so spacing and brackets that change nothing are set
aside too).

- A built-in algorithm (``fsm/algorithms``) is matched on every parameter's value for the
  profile the run is on.
- A lab's starter (``labs/starters``) is matched on its ``FILL IN`` parameters only: a starter
  whose FILL IN values are as shipped is the starter, whatever else was tuned; one whose FILL
  IN values the student set is the student's. An FSM shaped as a starter is judged as that
  starter, not as a built-in (a starter completed as the lab asks may well behave as the
  built-in it was cut from, and it is still the student's work), unless its file declares
  the built-in's own parameter defaults too: then it is that built-in, copied.
"""

from __future__ import annotations

import ast
import hashlib
from collections.abc import Callable, Iterator, Mapping
from dataclasses import dataclass, replace
from functools import cache
from pathlib import Path

from workbench.files.bundled import STARTER_DIR

from .algorithms import ALGORITHM_DIR
from .definition import (
    Action,
    FsmDefinition,
    MotorAction,
    MoveAction,
    Parameter,
    SetAction,
    State,
    TimerAction,
    TransitionDef,
    TurnAction,
    WheelsAction,
    resolve_params,
)
from .yaml_file import FsmFileError, load_fsm

#: a starter's parameter for the student to set says so at the start of its description
FILL_IN = "FILL IN"


def canonical_names(definition: FsmDefinition) -> dict[str, str]:
    """Each state's name in the order a run could reach it: the initial state ``S0``, then
    the targets of each state's transitions in the order they are written, breadth first;
    states no transition reaches follow in their names' order. Two machines that differ only
    in what their states are called, or in the order the states are written, get the same
    names."""
    by_name = {s.name: s for s in definition.states}
    order: list[str] = []
    queue = [definition.initial]
    while queue:
        name = queue.pop(0)
        if name in order or name not in by_name:
            continue
        order.append(name)
        queue += [t.target for t in by_name[name].transitions]
    order += sorted(n for n in by_name if n not in order)
    return {name: f"S{i}" for i, name in enumerate(order)}


#: the fields of each kind of action that hold an expression
EXPRESSIONS: dict[type, tuple[str, ...]] = {
    WheelsAction: ("left", "right"),
    MotorAction: ("power",),
    MoveAction: ("power",),
    TurnAction: ("degrees",),
    TimerAction: ("seconds",),
}


def _ordered_states(definition: FsmDefinition) -> list[State]:
    names = canonical_names(definition)
    return sorted(definition.states, key=lambda s: int(names[s.name][1:]))


def _texts(definition: FsmDefinition) -> Iterator[str]:
    """Every expression and assigned name of the machine, in the order a reader meets them
    going through the states as a run reaches them."""
    for state in _ordered_states(definition):
        for action in state.on_enter:
            if isinstance(action, SetAction):
                for name, text in action.assignments:
                    yield name
                    yield text
            for field_name in EXPRESSIONS.get(type(action), ()):
                yield getattr(action, field_name)
        for transition in state.transitions:
            yield transition.when
            for name, text in transition.set:
                yield name
                yield text
    for variable in definition.variables:
        yield variable.initial


def _read_names(text: str) -> list[str]:
    try:
        tree = ast.parse(text.strip(), mode="eval")
    except (SyntaxError, ValueError, RecursionError, MemoryError):
        return []
    return [node.id for node in ast.walk(tree) if isinstance(node, ast.Name)]


def fresh_names(definition: FsmDefinition) -> dict[str, str]:
    """A new name for each sensor (``s0``...), parameter (``p0``...) and variable (``v0``...),
    numbered in the order the expressions first read them; those no expression reads follow,
    in the order of what they hold, not of what they are called."""
    sensors = {n.name: repr((n.kind, n.mount, sorted(n.ports.items()))) for n in definition.sensors}
    params = {
        p.name: repr((p.minimum, p.maximum, sorted(p.defaults.items())))
        for p in definition.parameters
    }
    variables = {v.name: repr(v.initial) for v in definition.variables}
    kinds = (("s", sensors), ("p", params), ("v", variables))
    met: list[str] = []
    for text in _texts(definition):
        for name in _read_names(text):
            if name not in met:
                met.append(name)
    fresh: dict[str, str] = {}
    for prefix, held in kinds:
        order = [n for n in met if n in held]
        order += sorted((n for n in held if n not in order), key=lambda n: (held[n], n))
        fresh.update({name: f"{prefix}{i}" for i, name in enumerate(order)})
    return fresh


def _renamer(fresh: Mapping[str, str]) -> Callable[[str], str]:
    def rename(text: str) -> str:
        if text in fresh:
            return fresh[text]
        try:
            tree = ast.parse(text.strip(), mode="eval")
        except (SyntaxError, ValueError, RecursionError, MemoryError):
            return text
        for node in ast.walk(tree):
            if isinstance(node, ast.Name) and node.id in fresh:
                node.id = fresh[node.id]
        try:
            return ast.unparse(tree)
        except (RecursionError, ValueError):
            return text

    return rename


def _renamed_action(action: Action, rename: Callable[[str], str]) -> Action:
    if isinstance(action, SetAction):
        return SetAction(tuple((rename(n), rename(t)) for n, t in action.assignments))
    fields = EXPRESSIONS.get(type(action), ())
    return replace(action, **{f: rename(getattr(action, f)) for f in fields})  # type: ignore[arg-type]


def _renamed_transition(
    transition: TransitionDef, states: Mapping[str, str], rename: Callable[[str], str]
) -> TransitionDef:
    return replace(
        transition,
        target=states.get(transition.target, transition.target),
        when=rename(transition.when) if transition.when else "",
        set=tuple((rename(n), rename(t)) for n, t in transition.set),
    )


def shape(definition: FsmDefinition) -> str:
    """What an FSM does, without what does not change its behaviour (names, descriptions
    and the states' names among them, the order of its unordered parts and the parameters'
    values)."""
    names = canonical_names(definition)
    fresh = fresh_names(definition)
    rename = _renamer(fresh)
    states = [
        replace(
            s,
            name=names[s.name],
            description="",
            on_enter=tuple(_renamed_action(a, rename) for a in s.on_enter),
            transitions=tuple(_renamed_transition(t, names, rename) for t in s.transitions),
        )
        for s in _ordered_states(definition)
    ]
    sensors = sorted(
        (fresh[n.name], n.kind, n.mount, tuple(sorted(n.ports.items()))) for n in definition.sensors
    )
    params = sorted((fresh[p.name], p.minimum, p.maximum) for p in definition.parameters)
    variables = sorted((fresh[v.name], rename(v.initial)) for v in definition.variables)
    return repr((names.get(definition.initial), states, sensors, params, variables))


def declared(definition: FsmDefinition) -> str:
    """The parameter defaults an FSM file declares, every profile's, under their fresh names."""
    fresh = fresh_names(definition)
    return repr(sorted((fresh[p.name], sorted(p.defaults.items())) for p in definition.parameters))


@dataclass(frozen=True)
class BundledFsm:
    """An FSM file the workbench ships: where it is (as the reason names it), its shape, and
    the parameters that must keep their values for a run to be this file's."""

    shown: str
    shape: str
    definition: FsmDefinition
    #: its declared parameter defaults (:func:`declared`)
    defaults: str
    #: None: every parameter; else only these (a starter's FILL IN parameters)
    pinned: frozenset[str] | None
    #: its names and their fresh names (:func:`fresh_names`)
    fresh: Mapping[str, str]

    def matches(self, run_shape: str, values: Mapping[str, float], profile: str) -> bool:
        """Whether a run of this shape, with ``values`` (by the fresh names of
        :func:`fresh_names`) in force, is this file's."""
        if run_shape != self.shape:
            return False
        try:
            own = resolve_params(self.definition, profile)
        except ValueError:
            return False
        names = own.keys() if self.pinned is None else self.pinned
        return all(values.get(self.fresh[name]) == own.get(name) for name in names)


def _fill_ins(parameters: tuple[Parameter, ...]) -> frozenset[str]:
    return frozenset(p.name for p in parameters if p.description.strip().startswith(FILL_IN))


@cache
def bundled_fsms() -> tuple[BundledFsm, ...]:
    """Every built-in algorithm and every lab starter, read once."""
    found: list[BundledFsm] = []
    for folder, label, starters in (
        (ALGORITHM_DIR, "built-in algorithm", False),
        (STARTER_DIR, "lab starter", True),
    ):
        for path in sorted(Path(folder).glob("*.yaml")):
            try:
                definition = load_fsm(path)
            except FsmFileError:
                continue
            pinned = _fill_ins(definition.parameters) if starters else None
            shown = f"the {label} {path.parent.name}/{path.name}"
            found.append(
                BundledFsm(
                    shown,
                    shape(definition),
                    definition,
                    declared(definition),
                    pinned,
                    fresh_names(definition),
                )
            )
    return tuple(found)


def bundled_fsm(definition: FsmDefinition, values: Mapping[str, float], profile: str) -> str:
    """Which shipped FSM ``definition`` with the parameters ``values`` in force is, in words
    ("the built-in algorithm algorithms/right-wall.yaml"); "" when it is none of them."""
    run_shape, run_defaults = shape(definition), declared(definition)
    fresh = fresh_names(definition)
    values = {fresh.get(name, name): value for name, value in values.items()}
    known = bundled_fsms()
    copied = [
        b for b in known
        if b.pinned is None and b.shape == run_shape and b.defaults == run_defaults
    ]  # fmt: skip
    starters = [b for b in known if b.pinned is not None and b.shape == run_shape]
    for bundled in copied or starters or known:
        if bundled.matches(run_shape, values, profile):
            return bundled.shown
    return ""


def fsm_digest(definition: FsmDefinition, overrides: Mapping[str, float]) -> str:
    """The digest of an FSM as it runs: the sha256 of its file's text as read; when
    parameters were set for the run, the sha256 of that digest, a newline and one
    ``NAME=VALUE`` line per parameter set, sorted. "" when it was not read from a file."""
    if not definition.digest:
        return ""
    if not overrides:
        return definition.digest
    lines = "".join(f"{name}={float(value)!r}\n" for name, value in sorted(overrides.items()))
    return hashlib.sha256(f"{definition.digest}\n{lines}".encode()).hexdigest()
