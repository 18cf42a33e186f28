"""Which FSM that comes with the workbench a definition is, behaviour for behaviour.

A lab's "your program" objectives must rest on the student's own work, so a run by an FSM
that is one the workbench ships is not theirs, whatever the file is called. Two FSMs are the
same here when they behave the same: their states, actions, transitions, sensors, variables
and parameter ranges are equal once names (the states' too: they are named in the order a run
reaches them), descriptions and the order of the parts that have no order (sensors,
parameters, variables, states other than the initial one) are set aside, and the parameters
in force have the same values.

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

import hashlib
from collections.abc import Mapping
from dataclasses import dataclass, replace
from functools import cache
from pathlib import Path

from workbench.files.bundled import STARTER_DIR

from .algorithms import ALGORITHM_DIR
from .definition import FsmDefinition, Parameter, resolve_params
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


def shape(definition: FsmDefinition) -> str:
    """What an FSM does, without what does not change its behaviour (names, descriptions
    and the states' names among them, the order of its unordered parts and the parameters'
    values)."""
    names = canonical_names(definition)
    states = sorted(
        (
            replace(
                s,
                name=names[s.name],
                description="",
                transitions=tuple(
                    replace(t, target=names.get(t.target, t.target)) for t in s.transitions
                ),
            )
            for s in definition.states
        ),
        key=lambda s: int(s.name[1:]),
    )
    sensors = sorted(
        (n.name, n.kind, n.mount, tuple(sorted(n.ports.items()))) for n in definition.sensors
    )
    params = sorted((p.name, p.minimum, p.maximum) for p in definition.parameters)
    variables = sorted((v.name, v.initial) for v in definition.variables)
    return repr((names.get(definition.initial), states, sensors, params, variables))


def declared(definition: FsmDefinition) -> str:
    """The parameter defaults an FSM file declares, every profile's."""
    return repr(sorted((p.name, sorted(p.defaults.items())) for p in definition.parameters))


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

    def matches(self, run_shape: str, values: Mapping[str, float], profile: str) -> bool:
        if run_shape != self.shape:
            return False
        try:
            own = resolve_params(self.definition, profile)
        except ValueError:
            return False
        names = own.keys() if self.pinned is None else self.pinned
        return all(values.get(name) == own.get(name) for name in names)


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
                BundledFsm(shown, shape(definition), definition, declared(definition), pinned)
            )
    return tuple(found)


def bundled_fsm(definition: FsmDefinition, values: Mapping[str, float], profile: str) -> str:
    """Which shipped FSM ``definition`` with the parameters ``values`` in force is, in words
    ("the built-in algorithm algorithms/right-wall.yaml"); "" when it is none of them."""
    run_shape, run_defaults = shape(definition), declared(definition)
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
