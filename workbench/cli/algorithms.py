"""``workbench algorithms``: the built-in maze algorithms, their sensors and parameters."""

from __future__ import annotations

import argparse
import json
import sys
import textwrap

from workbench.fsm.algorithms import list_algorithms, load_algorithm
from workbench.fsm.machine import PROFILES, FsmDefinition, Parameter, SensorNeed
from workbench.fsm.yaml_file import FsmFileError


def register(sub: argparse._SubParsersAction) -> None:
    cmd = sub.add_parser(
        "algorithms",
        help="list the built-in maze algorithms with their sensors and parameters",
        description="List the built-in maze algorithms (or the FSM files given) with what they "
        "do, the sensors they need and their parameters' defaults for each profile.",
    )
    cmd.add_argument(
        "names", nargs="*", metavar="NAME", help="only these algorithms, or paths to FSM files"
    )
    cmd.add_argument("--json", action="store_true", help="print one JSON document")
    cmd.set_defaults(func=cmd_algorithms)


def describe(defn: FsmDefinition) -> dict:
    return {
        "name": defn.name,
        "description": defn.description,
        "sensors": [
            {"name": s.name, "kind": s.kind, "mount": s.mount, "ports": dict(s.ports)}
            for s in defn.sensors
        ],
        "parameters": [
            {
                "name": p.name,
                "defaults": {k: p.defaults[k] for k in PROFILES if k in p.defaults},
                "min": p.minimum,
                "max": p.maximum,
                "description": p.description,
            }
            for p in defn.parameters
        ],
        "variables": {v.name: v.initial for v in defn.variables},
        "initial": defn.initial,
        "states": [s.name for s in defn.states],
    }


def render(defn: FsmDefinition, width: int = 92) -> str:
    wrap = textwrap.TextWrapper(width=width, initial_indent="  ", subsequent_indent="  ")
    lines = [defn.name, wrap.fill(defn.description)] if defn.description else [defn.name]
    lines.append("  sensors:" if defn.sensors else "  sensors: none")
    lines += [f"    {_sensor(s)}" for s in defn.sensors]
    if defn.parameters:
        lines.append(f"  parameters (defaults for {' / '.join(PROFILES)}):")
        text = textwrap.TextWrapper(width=width, initial_indent=" " * 8, subsequent_indent=" " * 8)
        for p in defn.parameters:
            lines.append(f"    {p.name} = {_defaults(p)}{_range(p)}")
            if p.description:
                lines.append(text.fill(p.description))
    states = f"states: {', '.join(s.name for s in defn.states)} (starts in {defn.initial})"
    lines.append(textwrap.fill(states, width, initial_indent="  ", subsequent_indent="    "))
    return "\n".join(lines)


def _sensor(s: SensorNeed) -> str:
    ports = [s.ports.get(p) for p in PROFILES]
    if len(set(ports)) == 1:
        where = f"port {ports[0]}"
    else:
        where = "port " + " / ".join(str(p) if p is not None else "-" for p in ports)
    return f"{s.name}: {s.kind} sensor mounted {s.mount}, {where}"


def _defaults(p: Parameter) -> str:
    return " / ".join(f"{p.defaults[k]:g}" if k in p.defaults else "-" for k in PROFILES)


def _range(p: Parameter) -> str:
    if p.minimum is None and p.maximum is None:
        return ""
    if p.maximum is None:
        return f"   (at least {p.minimum:g})"
    if p.minimum is None:
        return f"   (at most {p.maximum:g})"
    return f"   ({p.minimum:g} to {p.maximum:g})"


def cmd_algorithms(args: argparse.Namespace) -> int:
    try:
        defs = [load_algorithm(name) for name in (args.names or list_algorithms())]
    except FsmFileError as exc:
        print(exc, file=sys.stderr)
        return 1
    if args.json:
        print(json.dumps([describe(d) for d in defs], indent=2))
    else:
        print("\n\n".join(render(d) for d in defs))
    return 0
