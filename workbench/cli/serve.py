"""``workbench serve``: the simulation in real time, driven by a VIPLE program, without a TUI.

TCP (the Unity-simulator role) listens on 127.0.0.1 and ::1 port 1350 by default;
``--tcp-port 0`` turns it off. ``--ws-url`` adds the Web-Simulator role. Logging goes to
stderr: connections, rejections, and a status line every few seconds. Ctrl+C or SIGTERM stop
it cleanly (exit 0) and the run record, if any, ends with a summary line.
"""

from __future__ import annotations

import argparse
import asyncio
import contextlib
import logging
import signal
import sys
from dataclasses import dataclass, field
from typing import Any

from workbench.control.lifecycle import Run, record_file
from workbench.files.bundled import default_maze_path
from workbench.sim.clock import Pacer
from workbench.sim.driver import Driver
from workbench.sim.maze import MazeError
from workbench.sim.mazeio import load_maze
from workbench.sim.noise import noise_settings
from workbench.sim.profiles import NOISE_LEVELS, PROFILES, get_profile
from workbench.sim.sensors import SensorConfigError, SensorSpec, check_ports
from workbench.sim.session import Session
from workbench.sim.world import WorldError
from workbench.viple.hosting import Endpoints
from workbench.viple.link import (
    IDLE_S_DEFAULT,
    REPORT_MS_DEFAULT,
    REPORT_MS_MAX,
    REPORT_MS_MIN,
    LinkStatus,
    check_idle_s,
    check_report_ms,
)
from workbench.viple.tcp_server import DEFAULT_PORT, TcpConfig
from workbench.viple.ws_client import WsConfig

#: how often the simulation is advanced on the event loop, and the status line's period
TICK_HZ = 60.0
STATUS_SECONDS = 5.0

log = logging.getLogger("workbench.serve")


class ServeSetupError(ValueError):
    """``workbench serve`` cannot start with these options."""


@dataclass
class ServePlan:
    session: Session
    tcp: TcpConfig | None
    ws: WsConfig | None
    record: str | None = None
    fields: dict[str, Any] = field(default_factory=dict)


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "serve",
        help="let a VIPLE program drive the simulated robot (no TUI)",
        description="Run the simulation in real time and let an unmodified VIPLE program drive "
        "it: as VIPLE's Unity simulator (TCP, VIPLE connects to localhost:1350) and/or as its "
        "Web Simulator (connect to VIPLE's WebSocket server with --ws-url).",
    )
    p.add_argument(
        "--maze",
        default=argparse.SUPPRESS,
        help="maze file (default: the bundled Unity maze)",
    )
    p.add_argument("--profile", choices=list(PROFILES), help="default: the maze's, else unity")
    p.add_argument(
        "--sensor",
        action="extend",
        nargs="+",
        default=[],
        metavar="KIND:PORT:MOUNT",
        help="e.g. distance:1:right (default: the profile's sensors)",
    )
    p.add_argument(
        "--tcp-port",
        type=_whole_number("--tcp-port"),
        default=DEFAULT_PORT,
        metavar="PORT",
        help=f"TCP port VIPLE connects to (default {DEFAULT_PORT}; 0 turns TCP off)",
    )
    p.add_argument(
        "--ws-url",
        metavar="URL",
        help="also connect to VIPLE's WebSocket server, e.g. ws://localhost:8124/",
    )
    p.add_argument(
        "--report-ms",
        type=_whole_number("--report-ms"),
        default=REPORT_MS_DEFAULT,
        metavar="MS",
        help=f"sensor report interval ({REPORT_MS_MIN}-{REPORT_MS_MAX}, "
        f"default {REPORT_MS_DEFAULT})",
    )
    p.add_argument(
        "--bind",
        action="extend",
        nargs="+",
        default=[],
        metavar="ADDR",
        help="listen on these addresses instead of 127.0.0.1 and ::1 (e.g. 0.0.0.0)",
    )
    p.add_argument(
        "--driver-idle",
        type=float,
        default=IDLE_S_DEFAULT,
        metavar="SECONDS",
        help="a program that sends nothing and reads no reports for this long loses the "
        f"robot, which stops (default {IDLE_S_DEFAULT:g}; 0 never)",
    )
    p.add_argument("--record", metavar="FILE.jsonl", help="write the run record")
    p.add_argument("--seed", type=_whole_number("--seed"), default=0)
    p.add_argument(
        "--noise", choices=list(NOISE_LEVELS), help="default: the profile's (erobotic off)"
    )
    p.add_argument("-v", "--verbose", action="store_true", help="also log every command received")
    p.set_defaults(func=cmd_serve)


def _whole_number(option: str):
    def parse(text: str) -> int:
        try:
            return int(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"{text!r} is not a whole number") from None

    parse.__name__ = option
    return parse


# ---------------------------------------------------------------------------------------------
# Setting up


def plan(args: argparse.Namespace) -> ServePlan:
    """Check every option and build the session; bad input is a :class:`ServeSetupError`."""
    maze_path = getattr(args, "maze", None) or str(default_maze_path())
    try:
        maze = load_maze(maze_path)
    except MazeError as exc:
        raise ServeSetupError(str(exc)) from None
    problems = maze.validate()
    if problems:
        raise ServeSetupError("\n".join(str(p) for p in problems))
    tcp, ws = _endpoint_configs(args)
    try:
        profile = get_profile(args.profile or maze.profile or "unity")
        sensors = check_ports(SensorSpec.parse(s) for s in args.sensor) if args.sensor else None
        noise = noise_settings(args.noise or profile.noise, profile)
        session = Session(maze, profile.name, sensors, noise, args.seed)
    except (SensorConfigError, WorldError, ValueError) as exc:
        raise ServeSetupError(str(exc)) from None
    return ServePlan(session, tcp, ws, args.record, {"maze_path": maze_path})


def _endpoint_configs(args: argparse.Namespace) -> tuple[TcpConfig | None, WsConfig | None]:
    try:
        report_ms = check_report_ms(args.report_ms)
    except ValueError as exc:
        raise ServeSetupError(f"--report-ms: {exc}") from None
    if not 0 <= args.tcp_port <= 65535:
        raise ServeSetupError(
            f"--tcp-port {args.tcp_port} is out of range: use 1 to 65535 (0 turns TCP off)"
        )
    if args.tcp_port == 0 and args.bind:
        raise ServeSetupError("--bind needs TCP: it cannot be used with --tcp-port 0")
    if args.tcp_port == 0 and args.ws_url is None:
        raise ServeSetupError("--tcp-port 0 turns TCP off: give --ws-url, or a TCP port")
    idle_s = _idle_s(args.driver_idle)
    try:
        ws = (
            WsConfig(url=args.ws_url, report_ms=report_ms, idle_s=idle_s)
            if args.ws_url is not None
            else None
        )
    except ValueError as exc:
        raise ServeSetupError(f"--ws-url: {exc}") from None
    try:
        tcp = (
            TcpConfig(port=args.tcp_port, bind=tuple(args.bind), report_ms=report_ms, idle_s=idle_s)
            if args.tcp_port
            else None
        )
    except ValueError as exc:
        raise ServeSetupError(f"--bind: {exc}") from None
    return tcp, ws


def _idle_s(seconds: float) -> float | None:
    if seconds == 0:
        return None
    try:
        return check_idle_s(seconds)
    except ValueError:
        raise ServeSetupError(
            f"--driver-idle {seconds:g} is not a usable time: give seconds above 0, or 0 for no "
            "limit"
        ) from None


# ---------------------------------------------------------------------------------------------
# Running


def cmd_serve(args: argparse.Namespace) -> int:
    logger = logging.getLogger("workbench")
    level = logger.level
    handler = _log_to_stderr(logging.DEBUG if args.verbose else logging.INFO)
    try:
        try:
            the_plan = plan(args)
        except ServeSetupError as exc:
            print(f"workbench serve: {exc}", file=sys.stderr)
            return 2
        try:
            return asyncio.run(serve(the_plan))
        except KeyboardInterrupt:
            return 0  # where signal handlers are not available, serve() has cleaned up
    finally:
        logger.removeHandler(handler)
        logger.setLevel(level)


def _log_to_stderr(level: int) -> logging.Handler:
    handler = logging.StreamHandler(sys.stderr)
    handler.setFormatter(logging.Formatter("%(asctime)s %(levelname)s %(message)s", "%H:%M:%S"))
    root = logging.getLogger("workbench")
    root.addHandler(handler)
    root.setLevel(level)
    return handler


async def serve(the_plan: ServePlan, stop: asyncio.Event | None = None) -> int:
    """Run until ``stop`` is set (or SIGINT / SIGTERM); 0 on a clean stop, 1 when an
    endpoint cannot start."""
    session = the_plan.session
    stop = stop or asyncio.Event()
    loop = asyncio.get_running_loop()
    installed = _on_signals(loop, stop.set)
    endpoints = await Endpoints.open(session, the_plan.tcp, the_plan.ws)
    if endpoints.problems:
        for problem in endpoints.problems:
            print(f"workbench serve: {problem}", file=sys.stderr)
        await endpoints.close()
        _off_signals(loop, installed)
        return 1
    try:
        recorder = record_file(the_plan.record) if the_plan.record else None
    except OSError as exc:
        print(
            f"workbench serve: {the_plan.record}: cannot write the record: {exc.strerror}",
            file=sys.stderr,
        )
        await endpoints.close()
        _off_signals(loop, installed)
        return 2
    config = the_plan.tcp or the_plan.ws
    assert config is not None, "a plan has TCP, a WebSocket URL or both (_endpoint_configs)"
    the_run = Run.start(
        session,
        recorder,
        driver="VIPLE",
        driven_by=Driver.viple().as_json(),
        endpoints=[_endpoint_json(status) for status in endpoints.statuses()],
        report_ms=config.report_ms,
        **the_plan.fields,
    )
    _log_setup(session)
    tasks = [
        asyncio.create_task(run_realtime(Pacer(session)), name="pacer"),
        asyncio.create_task(_status_lines(session, endpoints), name="status"),
    ]
    try:
        await stop.wait()
        log.info("stopping")
    finally:
        for task in tasks:
            task.cancel()
        await asyncio.gather(*tasks, return_exceptions=True)
        statuses = endpoints.statuses()
        await endpoints.close()
        _finish_record(the_run, statuses)
        _off_signals(loop, installed)
    log.info("stopped: %s", status_line(session, statuses))
    return 0


async def run_realtime(pacer: Pacer, hz: float = TICK_HZ) -> None:
    """Advance the session by the loop's clock, ``hz`` times a second, until cancelled."""
    loop = asyncio.get_running_loop()
    last = loop.time()
    period = 1.0 / hz
    while True:
        await asyncio.sleep(period)
        now = loop.time()
        pacer.advance(now - last)
        last = now


async def _status_lines(
    session: Session, endpoints: Endpoints, every: float = STATUS_SECONDS
) -> None:
    while True:
        await asyncio.sleep(every)
        log.info("%s", status_line(session, endpoints.statuses()))


def status_line(session: Session, statuses: list[LinkStatus]) -> str:
    snap = session.snapshot()
    kinds = {s.port: s.kind for s in snap.sensors}
    sensors = " ".join(
        f"{port}:{kinds.get(port, '?')}={_value(value)}"
        for port, value in sorted(snap.readings.items())
    )
    pose = snap.pose
    links = "; ".join(_link_summary(status) for status in statuses)
    return (
        f"t {snap.time:.1f} s | pose x {pose.x:.2f} y {pose.y:.2f} heading {pose.heading:.0f}° "
        f"| sensors {sensors or 'none'} | driver {snap.driver} | {links}"
    )


def _value(value: float | int) -> str:
    return str(value) if isinstance(value, int) else f"{value:.3f}"


def _link_summary(status: LinkStatus) -> str:
    peer = status.peer or "no VIPLE"
    return (
        f"{status.role} {peer}: in {status.messages_in} out {status.messages_out} "
        f"invalid {status.invalid}"
    )


def _endpoint_json(status: LinkStatus) -> dict[str, Any]:
    return {"role": status.role, "address": status.address}


def _log_setup(session: Session) -> None:
    profile = session.profile
    sensors = ", ".join(str(s) for s in session.world.sensors) or "none"
    log.info(
        "maze %s, profile %s (%s), sensors %s, wheel ports left %d right %d, noise %s, seed %d",
        session.maze.name or session.maze.source,
        profile.name,
        profile.unit,
        sensors,
        profile.left_port,
        profile.right_port,
        session.world.noise.level,
        session.world.seed,
    )


def _finish_record(the_run: Run, statuses: list[LinkStatus]) -> None:
    try:
        the_run.end(
            endpoints=[
                {
                    "role": s.role,
                    "address": s.address,
                    "connections": s.connections,
                    "refused": s.refused,
                    "messages_in": s.messages_in,
                    "messages_out": s.messages_out,
                    "invalid": s.invalid,
                }
                for s in statuses
            ]
        )
    finally:
        the_run.close()


def _on_signals(loop: asyncio.AbstractEventLoop, callback) -> list[int]:
    installed: list[int] = []
    for sig in (signal.SIGINT, signal.SIGTERM):
        with contextlib.suppress(NotImplementedError, RuntimeError, ValueError):
            loop.add_signal_handler(sig, callback)
            installed.append(sig)
    return installed


def _off_signals(loop: asyncio.AbstractEventLoop, installed: list[int]) -> None:
    for sig in installed:
        with contextlib.suppress(Exception):
            loop.remove_signal_handler(sig)
