"""``workbench viple``: check and show VIPLE program files, and run one on a maze headless."""

from __future__ import annotations

import argparse
import asyncio
import contextlib
import json
import os
import sys

from workbench.control.headless import RunResult, RunSetupError, RunSpec, run
from workbench.program.interp import MAX_ERRORS, MAX_FIRED, Printed, ProgramController
from workbench.program.keys import KeyScriptError, parse_key_script, typed_events
from workbench.program.pilot import ProgramPilot, load_compiled
from workbench.program.problems import ProgramError
from workbench.program.remote import RemoteProgram, robot_settings, wheel_ports
from workbench.program.show import count, describe_program, one_line
from workbench.sim.profiles import get_profile
from workbench.viple.client import (
    ClientSetup,
    ClientSetupError,
    Step,
    parse_endpoint,
    run_client,
)
from workbench.viple.codec import WheelPorts

from . import picture as picture_cmd
from .common import report_ms_option
from .keyboard import QUIT_KEYS, attach_keyboard, raw_terminal
from .run import _simulation_options, describe_measures, report, run_head, with_picture


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
    r.add_argument(
        "--maze",
        help="maze file (any supported format) or a bundled maze's name; not with --connect",
    )
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
    report_ms_option(r)
    r.add_argument("--seed", type=int, default=0)
    r.add_argument("--max-time", type=float, help="simulated seconds (default: from maze size)")
    r.add_argument("--record", metavar="FILE.jsonl", help="write the run record")
    r.add_argument("--json", action="store_true", help="one JSON object")
    picture_cmd.picture_option(r, "the run's path on its maze (not with --connect)")
    r.add_argument(
        "--connect",
        nargs="?",
        const="robot",
        metavar="URL",
        help="drive a real robot or an external simulator over VIPLE's protocol, where the "
        "program's Robot activity says (Wi-Fi: TCP client of host:port; WebSocket: server on "
        "its port), or at URL (tcp://HOST:PORT to connect, ws://HOST:PORT to listen)",
    )
    r.add_argument(
        "--duration", type=float, metavar="S", help="with --connect: stop after S seconds"
    )
    r.add_argument(
        "--no-keyboard",
        action="store_true",
        help="with --connect: do not read the terminal's keys (they go to the program's Key "
        f"Press events when the input is a terminal; {QUIT_KEYS} stops the robot and quits)",
    )
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
            (
                count(len(program.activities), "activity", "activities"),
                count(len(program.panels), "panel"),
                count(len(program.links), "link"),
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
    if args.connect is not None:
        if args.picture:
            print(
                "workbench viple run: --picture draws a simulated run: leave it out with "
                "--connect, or record the run (--record) and draw it with workbench picture",
                file=sys.stderr,
            )
            return 2
        return cmd_connect(args)
    if not args.maze:
        print("workbench viple run: give --maze M (or --connect for a robot)", file=sys.stderr)
        return 2
    if args.max_time is not None and not 0 < args.max_time <= 24 * 3600:
        print("workbench viple run: --max-time must be above 0 and at most a day", file=sys.stderr)
        return 2
    spec = RunSpec(
        maze=args.maze,
        pilot=ProgramPilot(
            args.file,
            keys=args.keys,
            typed=args.typed,
            kinds=args.kinds,
            report_ms=args.report_ms,
        ),
        profile=args.profile,
        sensors=tuple(args.sensor),
        seed=args.seed,
        noise=args.noise,
        noise_params=tuple(args.noise_set),
        max_time=args.max_time,
        record=args.record,
    )
    if picture_cmd.refused(args.picture, "workbench viple run"):
        return 2
    kept = bool(spec.record)
    with picture_cmd.recorded(spec) if args.picture else contextlib.nullcontext(spec) as spec:
        try:
            result = run(spec)
        except ProgramError as exc:
            for problem in exc.problems:
                print(problem, file=sys.stderr)
            return 2
        except RunSetupError as exc:
            print(f"workbench viple run: {exc}", file=sys.stderr)
            return 2
        code = report(result, args.json, describe_program_run)
        return with_picture(code, spec, args.picture, "workbench viple run", kept)


#: how many printed lines a run's summary shows from the start and from the end
FIRST_PRINTED = 5
LAST_PRINTED = 10
#: how many events and errors it lists
LISTED = 10


def describe_program_run(result: RunResult) -> str:
    program = result.driving.controller
    assert isinstance(program, ProgramController)
    lines = [run_head(result, result.driving.driver.name), *describe_measures(result)]
    if program.stopped is not None:
        lines.append(f"  STOPPED at {program.stopped}")
    lines += printed_summary(program)
    lines += unpressed_keys(program)
    lines += _listed(
        "events",
        [f"{f.time:7.2f} s  {one_line(f.what, 64)}" for f in program.fired],
        MAX_FIRED,
    )
    lines += _listed("errors", [one_line(str(e), 1000) for e in program.errors], MAX_ERRORS)
    return "\n".join(lines)


def unpressed_keys(program: ProgramController) -> list[str]:
    """What to do when the program answers keys and none of its Key Press events fired (a
    program that starts on a key does nothing in a headless run without ``--keys``)."""
    key_sets = program.compiled.key_sets
    wanted = sorted({"+".join(sorted(keys)) for keys in key_sets.values() if keys})
    fired = program.fired
    if not wanted or len(fired) >= MAX_FIRED or any(f.activity in key_sets for f in fired):
        return []
    return [
        f"  no key event fired: the program answers {', '.join(wanted)} (Key Press); press "
        f'one with --keys "{wanted[0]}@0.5"'
    ]


def _printed_line(p: Printed) -> str:
    return f"    {p.time:7.2f} s  {one_line(p.text, 63)}"


def printed_summary(program: ProgramController) -> list[str]:
    """What Print Line printed: every line, or the first and the last few with what lies
    between them said in numbers and simulated times."""
    total = program.printed_total
    if not total:
        return []
    if total <= FIRST_PRINTED + LAST_PRINTED:
        return [f"  printed {count(total, 'line')}:", *map(_printed_line, program.printed)]
    recent = list(program.recent)
    first, last = program.printed[:FIRST_PRINTED], recent[-LAST_PRINTED:]
    hidden = total - FIRST_PRINTED - LAST_PRINTED
    since, until = program.printed[FIRST_PRINTED].time, recent[-LAST_PRINTED - 1].time
    return [
        f"  printed {total:,} lines; the first {FIRST_PRINTED} and the last {LAST_PRINTED}:",
        *map(_printed_line, first),
        f"    ... {count(hidden, 'line')} not shown (lines {FIRST_PRINTED + 1:,} to "
        f"{total - LAST_PRINTED:,}, printed from {since:.2f} s to {until:.2f} s)",
        *map(_printed_line, last),
    ]


def _listed(what: str, items: list[str], kept: int) -> list[str]:
    """``events: 3`` and the items, or the first LISTED of them, saying which."""
    if not items:
        return []
    n = f"{len(items):,}" if len(items) < kept else f"{kept:,} or more (no more are kept)"
    head = f"  {what}: {n}" + (f"; the first {LISTED}:" if len(items) > LISTED else ":")
    return [head, *(f"    {item}" for item in items[:LISTED])]


# -- driving a robot over the protocol ---------------------------------------------------------
class _ProgramBrain:
    """A :class:`RemoteProgram` as the VIPLE client's brain; prints what the program printed."""

    def __init__(self, remote: RemoteProgram, log) -> None:
        self.remote = remote
        self.log = log
        self.transitions = 0
        self._told_missing = False
        self._errors = 0

    @property
    def readings(self):
        return self.remote.readings

    @property
    def state(self) -> str | None:
        return self.remote.state

    @property
    def timing(self) -> bool:
        return self.remote.timing

    @property
    def errors(self) -> int:
        """The program's run-time errors so far, all counted."""
        return self.remote.controller.errors_total

    @property
    def stopped(self) -> str | None:
        """Where and why the program was stopped for good (None: it was not)."""
        stopped = self.remote.controller.stopped
        return None if stopped is None else str(stopped)

    def next_tick(self) -> float:
        return self.remote.next_tick()

    def start(self, t: float) -> Step:
        return self._step(t, self.remote.start(t), started=True)

    def report(self, t: float, readings, text: str) -> Step:
        missing = self.remote.missing_ports(readings)
        if missing and not self._told_missing:
            self._told_missing = True
            have = ", ".join(str(p) for p in sorted(readings)) or "none"
            self.log(
                f"{t:8.2f} s  the reports carry no sensor on port(s) "
                f"{', '.join(map(str, missing))}, which the program reads (they carry {have})"
            )
        return self._step(t, self.remote.report(t, readings, text))

    def tick(self, t: float) -> Step:
        return self._step(t, self.remote.tick(t))

    def type_key(self, key: str, t: float) -> None:
        self.remote.type_key(key, t)

    def _step(self, t: float, commands, started: bool = False) -> Step:
        printed, fired = self.remote.news()
        self.transitions += len(fired)
        for f in fired:
            self.log(f"{f.time:8.2f} s  {one_line(f.what, 200)}")
        for p in printed:
            self.log(f"{p.time:8.2f} s  print: {one_line(p.text, 200)}")
        errors = self.remote.controller.errors
        for e in errors[self._errors :]:
            self.log(f"error at {e}")
        self._errors = len(errors)
        return Step(t, list(commands), started=started)


def cmd_connect(args: argparse.Namespace) -> int:
    name = "workbench viple run --connect"
    if args.maze:
        print(f"{name}: --maze is for simulated runs; the robot is the maze here", file=sys.stderr)
        return 2
    try:
        compiled = load_compiled(args.file, args.kinds)
        keys = parse_key_script(args.keys)
        if args.typed:
            typed = typed_events(parse_key_script(args.typed), until=float("inf"))
            keys = tuple(sorted(keys + typed, key=lambda e: e.time))
        if args.connect == "robot":
            robot = robot_settings(compiled)
            url = robot.url
        else:
            url = args.connect
        scheme = url.split(":", 1)[0].lower()
        if scheme not in ("tcp", "ws"):
            raise ClientSetupError(
                f"--connect {url!r} must be tcp://HOST:PORT (connect) or ws://HOST:PORT (listen)"
            )
        endpoint = parse_endpoint(
            connect=url if scheme == "tcp" else None, listen=url if scheme == "ws" else None
        )
        if args.duration is not None and not (0 < args.duration <= 24 * 3600):
            raise ClientSetupError("--duration must be above 0 and at most a day")
        profile = get_profile(args.profile or "unity")
    except ProgramError as exc:
        for problem in exc.problems:
            print(problem, file=sys.stderr)
        return 2
    except (KeyScriptError, ClientSetupError, ValueError) as exc:
        print(f"{name}: {exc}", file=sys.stderr)
        return 2
    progress = sys.stderr if args.json else sys.stdout
    keyboard = not args.no_keyboard and sys.stdin.isatty()
    # in raw mode the terminal no longer turns \n into a new line at the left margin
    newline = "\r\n" if keyboard and progress.isatty() else "\n"

    def log(text: str) -> None:
        progress.write(text.replace("\n", newline) + newline)
        progress.flush()

    ports = wheel_ports(compiled)
    made: list[_ProgramBrain] = []

    def brain() -> _ProgramBrain:
        made.append(_ProgramBrain(RemoteProgram(compiled, keys), log))
        return made[-1]

    setup = ClientSetup(
        definition=None,
        profile=profile,
        params={},
        sensors=(),
        binding={},
        endpoint=endpoint,
        duration=args.duration,
        brain=brain,
        title=os.path.basename(args.file),
        ports=WheelPorts(*ports) if ports else None,
    )
    wheels = setup.wheels
    log(
        f"{setup.name} over {endpoint} (wheels on ports {wheels.left}/{wheels.right}; "
        f"sha256 {compiled.program.digest[:16]}...)"
    )
    if keyboard:
        log(f"keys go to the program as you type them; {QUIT_KEYS} stops the robot and quits")
        fd = sys.stdin.fileno()
        with raw_terminal(fd):
            result = asyncio.run(run_client(setup, log, attach=attach_keyboard(fd)))
    else:
        result = asyncio.run(run_client(setup, log))
    program = made[-1] if made else None
    data = {**result.as_dict(), "program_sha256": compiled.program.digest}
    data["events"] = data.pop("transitions")
    # the robot over the wire is no simulated profile: a profile is named only when one was
    # given (its wheel ports serve a program whose Robot Drive names none)
    data["profile"] = args.profile
    data["errors"] = program.errors if program is not None else 0
    data["stopped"] = program.stopped if program is not None else None
    if args.json:
        print(json.dumps(data))
    elif result.ended != "no connection":
        print(
            "\n".join(
                [
                    f"summary: {setup.name} over {result.endpoint}",
                    f"  ended           {result.message or result.ended}",
                    f"  driven for      {result.time:.1f} s",
                    f"  reports         {result.reports} received, {result.rejected} rejected",
                    f"  commands sent   {result.commands}",
                    f"  events          {result.transitions}",
                    f"  errors          {data['errors']}",
                    *([f"  STOPPED at      {data['stopped']}"] if data["stopped"] else []),
                ]
            )
        )
    if result.ended in ("no connection", "error"):
        print(f"{name}: {result.message}", file=sys.stderr)
    return result.exit_code
