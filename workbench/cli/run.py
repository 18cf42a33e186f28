"""``workbench run`` and ``workbench eval``: algorithms on mazes, headless, measured."""

from __future__ import annotations

import argparse
import contextlib
import dataclasses
import json
import os
import sys
import tempfile
from collections.abc import Callable, Sequence
from pathlib import Path

from workbench.control.evaluate import (
    EVAL_LIMITS,
    MIN_EVAL_MEMORY,
    Entrant,
    EvalError,
    algorithm_entrant,
    evaluate,
    format_narrow,
    format_table,
    write_csv,
)
from workbench.control.headless import (
    AlgorithmPilot,
    RunFailed,
    RunResult,
    RunSetupError,
    RunSpec,
    run,
)
from workbench.control.parallel import Limits
from workbench.program.interp import ProgramController
from workbench.program.keyfiles import program_keys, read_key_file
from workbench.program.keys import KeyScriptError, parse_key_script
from workbench.program.pilot import program_entrant
from workbench.sim.metrics import TURN_MIN_DEGREES
from workbench.sim.noise import NOISE_LEVELS
from workbench.sim.profiles import PROFILES
from workbench.sim.record import stop_words

from . import picture as picture_cmd
from .common import report_ms_option


def _simulation_options(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--profile", choices=list(PROFILES), help="default: the maze's, else unity")
    parser.add_argument(
        "--noise", choices=list(NOISE_LEVELS), help="default: the profile's (erobotic off)"
    )
    parser.add_argument(
        "--noise-set",
        action="append",
        default=[],
        metavar="NAME=VALUE",
        help="one noise parameter: motor_imbalance, turn_error, distance_relative, "
        "distance_absolute",
    )


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("run", help="run one algorithm on one maze and print its metrics")
    p.add_argument(
        "--maze",
        required=True,
        help="maze file (any supported format), or a bundled maze by name (web, erobotic, ...)",
    )
    p.add_argument("--algorithm", required=True, help="built-in name or an FSM .yaml file")
    _simulation_options(p)
    p.add_argument(
        "--sensor",
        action="append",
        default=[],
        metavar="KIND:PORT:MOUNT",
        help="e.g. distance:1:right (default: the algorithm's own sensors)",
    )
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--param", action="append", default=[], metavar="NAME=VALUE")
    p.add_argument("--max-time", type=float, help="simulated seconds (default: from maze size)")
    p.add_argument("--record", metavar="FILE.jsonl", help="write the run record")
    p.add_argument("--json", action="store_true", help="one JSON object")
    picture_cmd.picture_option(p, "the run's path on its maze")
    p.set_defaults(func=cmd_run)

    e = sub.add_parser(
        "eval", help="every algorithm and VIPLE program on every maze, over several seeds"
    )
    e.add_argument("--maze", nargs="+", required=True, metavar="M")
    e.add_argument("--algorithm", nargs="+", default=[], metavar="A")
    e.add_argument(
        "--program", nargs="+", default=[], metavar="FILE", help="VIPLE programs (.viple, .xml)"
    )
    e.add_argument(
        "--sensor",
        action="append",
        default=[],
        metavar="KIND:PORT:MOUNT",
        help="the robot's sensors for the programs (default: the profile's)",
    )
    key_options(e)
    e.add_argument("--kinds", metavar="MAP.yaml", help="names for unknown activity kinds")
    _simulation_options(e)
    report_ms_option(e)
    e.add_argument("--seeds", type=int, default=3, help="seeds 0..N-1 (default 3)")
    e.add_argument("--max-time", type=float, help="simulated seconds per run")
    e.add_argument("--jobs", type=int, default=os.cpu_count() or 1, help="parallel processes")
    e.add_argument(
        "--deadline",
        type=float,
        default=EVAL_LIMITS.deadline,
        metavar="S",
        help="wall-clock seconds one run may take before it is stopped "
        f"(default {EVAL_LIMITS.deadline:g})",
    )
    e.add_argument(
        "--memory",
        type=int,
        default=EVAL_LIMITS.memory,
        metavar="MIB",
        help="address space one run's process may map beyond the evaluator's, in MiB "
        f"(default {EVAL_LIMITS.memory})",
    )
    e.add_argument("--csv", metavar="FILE", help="also write the matrix as CSV")
    e.add_argument(
        "--wide", action="store_true", help="the table in one wide line per entrant (110 columns)"
    )
    e.add_argument("--json", action="store_true", help="one JSON object")
    picture_cmd.picture_option(
        e,
        "each maze's runs (seed 0) side by side, one picture per maze: with several mazes "
        "FILE-MAZE.svg beside FILE",
    )
    e.set_defaults(func=cmd_eval)


def key_options(parser: argparse.ArgumentParser) -> None:
    """``--keys`` and ``--keys-file``: the key script of the programs without their own."""
    keys = parser.add_mutually_exclusive_group()
    keys.add_argument(
        "--keys",
        default="",
        metavar="SCRIPT",
        help='keys pressed in every run of a program, e.g. "a@0.2 release@1" (a program\'s '
        "own NAME.keys file beside it comes first)",
    )
    keys.add_argument("--keys-file", metavar="FILE", help="the same, read from a file")


def common_keys(args: argparse.Namespace) -> str:
    """The key script ``--keys`` or ``--keys-file`` gives (KeyScriptError when it is bad)."""
    if args.keys_file:
        return read_key_file(args.keys_file)
    parse_key_script(args.keys)
    return str(args.keys)


def cmd_run(args: argparse.Namespace) -> int:
    spec = RunSpec(
        maze=args.maze,
        pilot=AlgorithmPilot(args.algorithm, tuple(args.param)),
        profile=args.profile,
        sensors=tuple(args.sensor),
        seed=args.seed,
        noise=args.noise,
        noise_params=tuple(args.noise_set),
        max_time=args.max_time,
        record=args.record,
    )
    if picture_cmd.refused(args.picture, "workbench run"):
        return 2
    kept = bool(spec.record)
    with picture_cmd.recorded(spec) if args.picture else contextlib.nullcontext(spec) as spec:
        try:
            result = run(spec)
        except (RunSetupError, RunFailed) as exc:
            print(f"workbench run: {exc}", file=sys.stderr)
            return 2
        code = report(result, args.json, describe_run(args.algorithm))
        return with_picture(code, spec, args.picture, "workbench run", kept)


def with_picture(code: int, spec: RunSpec, target: str | None, prog: str, kept: bool = True) -> int:
    """The run's exit code, or 2 when its ``--picture`` could not be drawn."""
    if not target or spec.record is None:
        return code
    drawn = picture_cmd.draw([spec.record], target, "path", prog, kept)
    return code if drawn == 0 else drawn


def report(result: RunResult, as_json: bool, describe: Callable[[RunResult], str]) -> int:
    """Print a finished run (as JSON or as ``describe`` words it); the exit code is 0 when the
    robot got out or the maze has no exit, 1 when it did not get out."""
    data = result.as_dict()
    print(json.dumps(data, sort_keys=False) if as_json else describe(result))
    return 0 if not result.maze.exits or data["reached_exit"] else 1


def describe_run(name: str) -> Callable[[RunResult], str]:
    """How ``workbench run`` words a run of the algorithm ``name`` (as it was given)."""

    def describe(result: RunResult) -> str:
        return "\n".join([run_head(result, name), *describe_measures(result)])

    return describe


def run_head(result: RunResult, name: str) -> str:
    """What ran, on which maze, with which profile and seed."""
    return f"{name} on {result.maze.name} ({result.profile}, seed {result.spec.seed})"


def _final_words(result: RunResult) -> str:
    """Where the driver was when the run was cut: an algorithm's state, or how many of a
    program's flows were still going."""
    state = result.as_dict()["final_state"]
    if not isinstance(result.driving.controller, ProgramController):
        return f"final state {state}"
    if state == "stopped":
        return "the program was stopped"
    return f"{state or '0 flows'} of the program still going"


def describe_measures(result: RunResult) -> list[str]:
    """The measures of a run, one per line (an algorithm's or a VIPLE program's)."""
    d = result.as_dict()
    m = result.metrics
    unit = PROFILES[result.profile].unit
    if d["reached_exit"]:
        outcome = f"reached the exit after {m['exit_time']:.1f} s"
    elif result.maze.exits:
        outcome = (
            f"did NOT get out within the {result.max_time:g} s limit "
            f"(the run was cut; {_final_words(result)})"
        )
    else:
        outcome = f"free exploration for {result.max_time:g} s (the maze has no exit)"
    eff = f"{d['efficiency']:.0%}" if d["efficiency"] is not None else "n/a"
    return [
        f"  {outcome}",
        f"  distance travelled  {d['distance']:.1f} {unit} ({d['distance_cells']:.1f} blocks)",
        f"  turning degrees     {d['turn_degrees']:.0f} deg in all; "
        f"{d['turns']} turn{'' if d['turns'] == 1 else 's'} of {TURN_MIN_DEGREES:.0f} deg or more",
        f"  collisions          {d['collisions']}",
        f"  touches             {d['touches']} (a touch sensor's bumper meeting a wall gently)",
        f"  efficiency          {eff} (shortest path / distance travelled)",
        f"  simulated time      {d['sim_time']:.1f} s",
        *(
            [f"  run record          {stop_words(result.record_stop)}"]
            if result.record_stop is not None
            else []
        ),
    ]


def cmd_eval(args: argparse.Namespace) -> int:
    if picture_cmd.refused(args.picture, "workbench eval"):
        return 2
    if args.seeds < 1 or args.jobs < 1:
        print("workbench eval: --seeds and --jobs must be at least 1", file=sys.stderr)
        return 2
    if not 0 < args.deadline <= 24 * 3600:
        print(
            "workbench eval: --deadline must be above 0 and at most a day (seconds)",
            file=sys.stderr,
        )
        return 2
    if args.memory < MIN_EVAL_MEMORY:
        print(f"workbench eval: --memory must be at least {MIN_EVAL_MEMORY} (MiB)", file=sys.stderr)
        return 2
    if not args.algorithm and not args.program:
        print(
            "workbench eval: give --algorithm A ... or --program FILE ... (or both)",
            file=sys.stderr,
        )
        return 2
    try:
        keys = common_keys(args)
        scripts = [program_keys(path, keys) for path in args.program]
    except KeyScriptError as exc:
        print(f"workbench eval: {exc}", file=sys.stderr)
        return 2
    bases = [os.path.basename(p) for p in args.program]
    programs = [
        program_entrant(
            path,
            name=base if bases.count(base) == 1 else path,
            kinds=args.kinds,
            profile=args.profile,
            sensors=tuple(args.sensor),
            noise=args.noise,
            noise_params=tuple(args.noise_set),
            max_time=args.max_time,
            keys=script,
            report_ms=args.report_ms,
        )
        for path, base, script in zip(args.program, bases, scripts, strict=True)
    ]
    try:
        result = evaluate(
            args.maze,
            args.algorithm,
            others=programs,
            seeds=args.seeds,
            profile=args.profile,
            noise=args.noise,
            noise_params=tuple(args.noise_set),
            max_time=args.max_time,
            jobs=args.jobs,
            limits=Limits(deadline=args.deadline, memory=args.memory),
            progress=not args.json and sys.stderr.isatty(),
        )
    except (EvalError, RunSetupError) as exc:
        print(f"workbench eval: {exc}", file=sys.stderr)
        return 2
    if args.csv:
        write_csv(args.csv, result)
    if args.json:
        print(json.dumps(result.as_dict(), sort_keys=False))
    else:
        print(format_table(result) if args.wide else format_narrow(result))
    if args.picture:
        entrants = [
            *(
                algorithm_entrant(a, args.profile, args.noise, tuple(args.noise_set), args.max_time)
                for a in args.algorithm
            ),
            *programs,
        ]
        return eval_pictures(args.picture, args.maze, entrants, "workbench eval")
    return 0


def eval_pictures(target: str, mazes: Sequence[str], entrants: Sequence[Entrant], prog: str) -> int:
    """One picture per maze of every entrant's run with seed 0 side by side (the run the
    table's first seed made: the same spec gives the same run)."""
    worst = 0
    for maze, path in zip(mazes, picture_cmd.maze_pictures(target, mazes), strict=True):
        with tempfile.TemporaryDirectory(prefix="workbench-picture-") as folder:
            records = []
            for k, entrant in enumerate(entrants):
                spec = dataclasses.replace(
                    entrant.spec(maze, 0), record=str(Path(folder) / f"{k + 1:02d}.jsonl")
                )
                run(spec)
                records.append(str(spec.record))
            worst = max(worst, picture_cmd.draw(records, str(path), "compare", prog))
    return worst
