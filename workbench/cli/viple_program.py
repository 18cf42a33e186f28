"""``workbench viple``: check and show VIPLE program files, and run one on a maze headless."""

from __future__ import annotations

import argparse
import json
import sys

from workbench.control.headless import RunSetupError
from workbench.program.headless import ProgramRunSpec, load_compiled, run_program
from workbench.program.problems import ProgramError
from workbench.program.show import describe_program

from .run import _simulation_options, describe_measures


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "viple", help="check, show or run VIPLE programs (.viple, VIPLE 3.x .xml) without VIPLE"
    )
    psub = p.add_subparsers(dest="viple_command", metavar="ACTION", required=True)

    c = psub.add_parser("check", help="load and check programs; list every problem")
    c.add_argument("files", nargs="+", metavar="FILE")
    c.add_argument("--kinds", metavar="MAP.yaml", help="names for unknown activity kinds")
    c.set_defaults(func=cmd_check)

    s = psub.add_parser("show", help="a program's panels, activities, values, links, globals")
    s.add_argument("file", metavar="FILE")
    s.add_argument("--kinds", metavar="MAP.yaml", help="names for unknown activity kinds")
    s.set_defaults(func=cmd_show)

    r = psub.add_parser("run", help="run a program on a maze and print its measures")
    r.add_argument("file", metavar="FILE")
    r.add_argument("--maze", required=True, help="maze file (any supported format)")
    _simulation_options(r)
    r.add_argument(
        "--sensor",
        action="append",
        default=[],
        metavar="KIND:PORT:MOUNT",
        help="the robot's sensors, e.g. distance:3:right (default: the profile's)",
    )
    r.add_argument("--keys", default="", metavar="SCRIPT", help='e.g. "w@0.5 release@3 a@4.2"')
    r.add_argument(
        "--typed",
        default="",
        metavar="SCRIPT",
        help='keys as a terminal sends them, e.g. "w@0.5 w@0.55 d@2": released after a quiet '
        "gap, as in the app",
    )
    r.add_argument("--kinds", metavar="MAP.yaml", help="names for unknown activity kinds")
    r.add_argument("--seed", type=int, default=0)
    r.add_argument("--max-time", type=float, help="simulated seconds (default: from maze size)")
    r.add_argument("--record", metavar="FILE.jsonl", help="write the run record")
    r.add_argument("--json", action="store_true", help="one JSON object")
    r.set_defaults(func=cmd_run)


def cmd_check(args: argparse.Namespace) -> int:
    bad = 0
    for path in args.files:
        try:
            compiled = load_compiled(path, args.kinds)
        except ProgramError as exc:
            bad += 1
            for problem in exc.problems:
                print(problem)
            continue
        program = compiled.program
        counts = ", ".join(
            _many(len(things), word)
            for things, word in (
                (program.activities, "activity"),
                (program.panels, "panel"),
                (program.links, "link"),
            )
        )
        print(f"{path}: ok (VIPLE {program.version}, {counts})")
    return 1 if bad else 0


def cmd_show(args: argparse.Namespace) -> int:
    try:
        compiled = load_compiled(args.file, args.kinds)
    except ProgramError as exc:
        for problem in exc.problems:
            print(problem, file=sys.stderr)
        return 1
    print("\n".join(describe_program(compiled.program)))
    return 0


def cmd_run(args: argparse.Namespace) -> int:
    if args.max_time is not None and not 0 < args.max_time <= 24 * 3600:
        print("workbench viple run: --max-time must be above 0 and at most a day", file=sys.stderr)
        return 2
    spec = ProgramRunSpec(
        program=args.file,
        maze=args.maze,
        profile=args.profile,
        sensors=tuple(args.sensor),
        keys=args.keys,
        typed=args.typed,
        kinds=args.kinds,
        seed=args.seed,
        noise=args.noise,
        noise_params=tuple(args.noise_set),
        max_time=args.max_time,
        record=args.record,
    )
    try:
        result = run_program(spec)
    except ProgramError as exc:
        for problem in exc.problems:
            print(problem, file=sys.stderr)
        return 2
    except RunSetupError as exc:
        print(f"workbench viple run: {exc}", file=sys.stderr)
        return 2
    data = result.as_dict()
    if args.json:
        print(json.dumps(data, sort_keys=False))
    else:
        print(describe_program_run(result))
    if not result.maze.exits:
        return 0
    return 0 if data["reached_exit"] else 1


def describe_program_run(result) -> str:
    d = result.as_dict()
    head = f"{result.program_name} on {result.maze.name} ({result.profile}, seed {d['seed']})"
    lines = [head, *describe_measures(result)]
    shown = result.printed[-10:]
    if result.printed:
        more = len(result.printed) + result.printed_dropped - len(shown)
        lines.append(
            f"  printed {len(result.printed) + result.printed_dropped} lines"
            + (f"; the last {len(shown)}:" if more else ":")
        )
        lines += [f"    {p.time:7.2f} s  {p.text[:60]}" for p in shown]
    if result.fired:
        lines.append(f"  events: {len(result.fired)}")
        lines += [f"    {f.time:7.2f} s  {f.what}" for f in result.fired[:10]]
    if result.errors:
        lines.append(f"  errors: {len(result.errors)}")
        lines += [f"    {e}" for e in result.errors[:10]]
    return "\n".join(lines)


def _many(count: int, word: str) -> str:
    """``1 panel``, ``5 panels``, ``32 activities``."""
    if count == 1:
        return f"1 {word}"
    return f"{count} {word[:-1]}ies" if word.endswith("y") else f"{count} {word}s"
