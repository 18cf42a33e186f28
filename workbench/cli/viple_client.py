"""``workbench viple-client``: a VIPLE stand-in that drives a simulator over VIPLE's protocol."""

from __future__ import annotations

import argparse
import asyncio
import json
import sys

from workbench.sim.commands import Command
from workbench.sim.profiles import PROFILES
from workbench.sim.record import command_json
from workbench.viple.client import (
    DEFAULT_CONNECT,
    EXIT_BAD_INPUT,
    ClientResult,
    ClientSetupError,
    Step,
    prepare,
    run_client,
)

EPILOG = """\
The client plays VIPLE: it sees only the sensor reports and sends only servo commands. Start
the simulator first (workbench serve), or with --listen start this first and point the
simulator at it (workbench serve --ws-url ws://localhost:8124/). Time is the client's own clock;
a Turn by Degree counts as done after the profile's turn time plus a margin, as a VIPLE program
waits for it with a Timer. Commands go as Robot Drive's two wheel powers (left and right port),
which a robot's own middleware understands: Move at Power becomes both wheels at its speed,
Turn by Degree a spin in place at the profile's turn rate, stopped when the angle's time is up.
--unity-simulator sends the Robot+ form instead (servoId -1), for VIPLE's Unity simulator.
The reports do not say when the robot is out of the maze: the run ends after --duration, when
the simulator closes the connection, or with Ctrl+C.

exit codes: 0 the run ended by --duration or by the simulator closing the connection;
1 no connection, the simulator closed before any report, the reports lack a sensor the FSM
reads, or the FSM failed; 2 bad input; 130 Ctrl+C (143 SIGTERM), after the summary."""


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "viple-client",
        help="drive a simulator over VIPLE's protocol with an algorithm, as VIPLE would",
        description="A VIPLE stand-in for people without Windows and for tests: runs a built-in "
        "or YAML algorithm on the VIPLE side of the protocol.",
        epilog=EPILOG,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument("--algorithm", required=True, help="built-in name or an FSM .yaml file")
    where = p.add_mutually_exclusive_group()
    where.add_argument(
        "--connect",
        metavar="tcp://HOST:PORT",
        help=f"connect to a simulator's TCP server (default {DEFAULT_CONNECT})",
    )
    where.add_argument(
        "--listen",
        metavar="ws://HOST:PORT",
        help="play VIPLE's WebSocket server; the simulator connects (e.g. ws://localhost:8124)",
    )
    p.add_argument("--profile", choices=list(PROFILES), default="unity", help="default unity")
    p.add_argument(
        "--unity-simulator",
        action="store_true",
        help="send the Unity simulator's Robot+ commands (Move at Power, Turn by Degree: "
        "servoId -1), which VIPLE's Unity simulator and workbench serve understand; without "
        "it every command is Robot Drive's two wheel powers on the profile's wheel ports, "
        "which a robot understands",
    )
    p.add_argument("--param", action="append", default=[], metavar="NAME=VALUE")
    p.add_argument(
        "--sensor",
        action="append",
        default=[],
        metavar="KIND:PORT:MOUNT",
        help="the sensors the simulator reports (default: the algorithm's own, as for serve)",
    )
    p.add_argument(
        "--duration", type=_seconds, metavar="S", help="stop S seconds after the robot is connected"
    )
    p.add_argument(
        "--json", action="store_true", help="print the summary as JSON (progress to stderr)"
    )
    p.set_defaults(func=cmd_viple_client)


def _seconds(text: str) -> float:
    try:
        return float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a number of seconds") from None


def cmd_viple_client(args: argparse.Namespace) -> int:
    try:
        setup = prepare(
            args.algorithm,
            profile=args.profile,
            params=args.param,
            sensors=args.sensor,
            connect=args.connect,
            listen=args.listen,
            duration=args.duration,
            unity_simulator=args.unity_simulator,
        )
    except ClientSetupError as exc:
        print(f"workbench viple-client: {exc}", file=sys.stderr)
        return EXIT_BAD_INPUT
    progress = sys.stderr if args.json else sys.stdout

    def log(text: str) -> None:
        print(text, file=progress, flush=True)

    def on_step(step: Step, state: str | None) -> None:
        log(describe_step(step, state))

    sensors = ", ".join(str(s) for s in setup.sensors)
    form = "commands as wheel powers" if setup.wheels_only else "Robot+ for the Unity simulator"
    log(
        f"{setup.name} ({setup.profile.name} profile, wheels on ports "
        f"{setup.profile.left_port}/{setup.profile.right_port}, {form}; sensors {sensors})"
    )
    result = asyncio.run(run_client(setup, log, on_step))
    if args.json:
        print(json.dumps(result.as_dict()))
    elif result.ended != "no connection":
        print(describe_result(result))
    if result.ended in ("no connection", "error"):
        print(f"workbench viple-client: {result.message}", file=sys.stderr)
    return result.exit_code


def describe_step(step: Step, state: str | None) -> str:
    text = f"{step.t:8.2f} s  "
    tr = step.transition
    if tr is None:
        text += f"start in {state}"
    else:
        text += f"{tr.source} -> {tr.target}"
        if tr.guard_text:
            values = ", ".join(f"{k}={_num(v)}" for k, v in tr.values.items())
            text += f"  [{tr.guard_text}" + (f": {values}]" if values else "]")
    if step.commands:
        text += "  sends " + "; ".join(_command_text(c) for c in step.commands)
    if step.turn_done_at is not None:
        text += f" (taken as done at {step.turn_done_at:.2f} s)"
    return text


def describe_result(result: ClientResult) -> str:
    readings = ", ".join(f"{k}={_num(v)}" for k, v in result.readings.items()) or "none"
    return "\n".join(
        [
            f"summary: {result.algorithm} over {result.endpoint} ({result.profile})",
            f"  ended           {result.message or result.ended}",
            f"  driven for      {result.time:.1f} s",
            f"  reports         {result.reports} received, {result.rejected} rejected",
            f"  commands sent   {result.commands}",
            f"  transitions     {result.transitions}, final state {result.final_state or '-'}",
            f"  last readings   {readings}",
        ]
    )


def _command_text(cmd: Command) -> str:
    ((kind, value),) = command_json(cmd).items()
    if kind == "stop":
        return "stop"
    if isinstance(value, dict):
        return f"{kind} {value['wheel']} {_num(value['power'])}"
    if isinstance(value, list):
        return f"{kind} {' '.join(_num(v) for v in value)}"
    return f"{kind} {_num(value)}"


def _num(value: object) -> str:
    return f"{value:.4g}" if isinstance(value, float) else str(value)
