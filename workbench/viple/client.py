"""A VIPLE stand-in: runs an FSM on the far side of the protocol, as a VIPLE program would.

The client sees only the sensor reports and sends only servo commands, so a run through it
exercises the whole loop: ``workbench serve`` (or the app) plays the simulator, this plays VIPLE.
It either connects to the simulator's TCP server (VIPLE's "Wi-Fi" connection, the Unity
simulator's role) or listens as VIPLE's WebSocket server, which the simulator connects to (the
Web Simulator's role).

Time is the client's own monotonic clock, counted from the moment the robot is connected; the
FSM's timers run on it, as VIPLE's Timer activities do. The FSM ticks on every report and at
least ``CONTROL_HZ`` times a second, with the latest readings.

A step (a start, a tick, a report) runs at one time on that clock, and its commands leave once
it has run. On the robot what counts is the time between commands: a 40 ms pulse is the 40 ms
between the two commands. So while a timer of the brain runs (:attr:`Brain.timing`), the
client holds each step's commands until its time plus the delay of the commands before it
(:class:`Departures`): a step that took long to run (or a late wake-up) never shortens the
time a timer says. Without a running timer, commands leave as soon as their step has run.

The protocol has no "turn finished" signal: a VIPLE program that uses Turn by Degree waits with
a Timer. The client does the same for the FSM's ``turn_done``: it raises the event
:func:`turn_wait` seconds after sending the turn, the profile's Turn by Degree time plus
``TURN_MARGIN_FRACTION`` of it (turn noise) plus ``TURN_MARGIN_S`` (the link and the
simulator's real-time pacing). Any other command sent before then abandons the turn, as it does
on the robot. Waiting a little long only leaves the robot standing still for that margin; a
wait too short would cut the turn off, so the margin errs on the long side.

Reports do not say when the robot reaches the exit, so the client cannot know: a run ends when
``duration`` has passed, when the simulator closes the connection, or when the user stops it
(a signal, or :meth:`VipleClient.stop` from a front end's quit key).

The FSM's commands go as Robot Drive's two wheel powers unless the set-up asks for the Unity
simulator's Robot+ form (``wheels_only``; see :mod:`workbench.viple.wheel_form`): a turn then
is a spin that the client stops when its time is up, woken for it as for a tick. A VIPLE
program's commands go as the program says, as VIPLE sends them.

Reports are read as they came (any JSON scalar as a value); a brain refuses one it cannot read
(an FSM, text where it needs a number) with a ``CodecError``, and the run goes on.

A brain that answers keys (:class:`TakesKeys`, a VIPLE program) gets the keys a front end hands
to :meth:`VipleClient.press`, on the client's clock, and ticks at once so the robot answers
without waiting for the next report.
"""

from __future__ import annotations

import asyncio
import contextlib
import errno
import json
import math
import signal
import socket
import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any, Protocol, runtime_checkable
from urllib.parse import urlsplit

from websockets.asyncio.server import ServerConnection, serve
from websockets.exceptions import ConnectionClosed

from workbench.fsm.algorithms import load_algorithm
from workbench.fsm.machine import (
    FsmController,
    FsmDefinition,
    FsmError,
    FsmRuntimeError,
    Transition,
    bind_sensors,
    preset_sensors,
)
from workbench.fsm.yaml_file import FsmFileError, parse_param_overrides
from workbench.sim.commands import Command, Stop, TurnByDegrees
from workbench.sim.profiles import Profile, get_profile
from workbench.sim.sensors import SensorConfigError, SensorSpec, check_ports

from .codec import (
    CodecError,
    FrameError,
    LineSplitter,
    SensorValue,
    WheelPorts,
    encode_command,
    parse_report,
    reading_number,
    split_frame,
)
from .wheel_form import WheelDrive

DEFAULT_CONNECT = "tcp://localhost:1350"
DEFAULT_PORTS = {"tcp": 1350, "ws": 8124}
#: the FSM ticks at least this often (the control rate of in-process runs)
CONTROL_HZ = 20.0
TURN_MARGIN_FRACTION = 0.1
TURN_MARGIN_S = 0.3
#: how long ``--connect`` keeps retrying while nothing listens, and how often
CONNECT_PATIENCE_S = 5.0
CONNECT_RETRY_S = 0.25
#: the longest delay of earlier commands that later ones are held for (see Departures); a
#: step runs in milliseconds (its activities are bounded), so more is the machine's stall
MAX_LAG_S = 0.25
#: rejected reports are printed one by one up to this many, then only counted
SHOWN_REJECTIONS = 10

EXIT_OK = 0
EXIT_FAILED = 1
EXIT_BAD_INPUT = 2


class ClientSetupError(ValueError):
    """The client cannot start: bad algorithm, profile, parameter, sensor, URL or duration."""


class ClientRunError(RuntimeError):
    """The run cannot go on: the reports lack a sensor the FSM reads, or the FSM failed."""


# ----------------------------------------------------------------------------- set-up


@dataclass(frozen=True)
class Endpoint:
    """Where the client meets the simulator: ``connect`` to a TCP server or ``listen`` for
    WebSocket connections (VIPLE's WebSocket Server)."""

    role: str
    host: str
    port: int

    @property
    def scheme(self) -> str:
        return "tcp" if self.role == "connect" else "ws"

    def __str__(self) -> str:
        host = f"[{self.host}]" if ":" in self.host else self.host
        tail = "/" if self.scheme == "ws" else ""
        return f"{self.scheme}://{host}:{self.port}{tail}"


def parse_endpoint(connect: str | None = None, listen: str | None = None) -> Endpoint:
    """``--connect tcp://HOST[:PORT]`` or ``--listen ws://HOST[:PORT][/]``; ports default to
    VIPLE's (1350 for the Unity simulator's TCP server, 8124 for the WebSocket server)."""
    if connect is not None and listen is not None:
        raise ClientSetupError("give either --connect or --listen, not both")
    if listen is not None:
        return _endpoint("listen", "--listen", listen, "ws")
    return _endpoint("connect", "--connect", connect or DEFAULT_CONNECT, "tcp")


def _endpoint(role: str, option: str, text: str, scheme: str) -> Endpoint:
    example = f"{scheme}://localhost:{DEFAULT_PORTS[scheme]}"
    shape = f"{option} {text!r} must be {scheme}://HOST:PORT, e.g. {example}"
    parts = urlsplit(text.strip())
    if parts.scheme != scheme or not parts.netloc:
        raise ClientSetupError(shape)
    try:
        port = parts.port
    except ValueError:
        port = 0

    if port == 0:
        raise ClientSetupError(f"{option} {text!r}: the port is not a number from 1 to 65535")
    if not parts.hostname:
        raise ClientSetupError(f"{shape} (the host is missing)")
    if parts.path not in ("", "/") or parts.query or parts.fragment:
        raise ClientSetupError(f"{shape} (nothing may follow the port)")
    return Endpoint(role, parts.hostname, port or DEFAULT_PORTS[scheme])


class Brain(Protocol):
    """What drives from the VIPLE side: an FSM (:class:`RemoteFsm`) or a VIPLE program."""

    transitions: int

    @property
    def readings(self) -> Mapping[Any, SensorValue] | None: ...

    @property
    def state(self) -> str | None: ...

    def start(self, t: float) -> Step: ...

    def report(self, t: float, readings: Mapping[int, SensorValue], text: str) -> Step:
        """A report arrived: its readings (port -> value, in its order) and its text as it
        arrived. A ``CodecError`` refuses the report (a value this brain cannot read)."""
        ...

    def next_tick(self) -> float: ...

    def tick(self, t: float) -> Step: ...

    @property
    def timing(self) -> bool:
        """Whether a timer of the brain runs (a Timer, a turn waited for): the time between
        its commands is then the brain's to say (see :class:`Departures`)."""
        ...


@runtime_checkable
class TakesKeys(Protocol):
    """A brain that answers keys typed while it drives (a VIPLE program's Key Press events)."""

    def type_key(self, key: str, t: float) -> None: ...


@dataclass(frozen=True)
class ClientSetup:
    definition: FsmDefinition | None
    profile: Profile
    params: dict[str, float]
    sensors: tuple[SensorSpec, ...]
    binding: dict[str, int]
    endpoint: Endpoint
    duration: float | None = None
    #: another brain than the FSM (a VIPLE program), its name, and its own wheel ports
    brain: Callable[[], Brain] | None = None
    title: str = ""
    ports: WheelPorts | None = None
    #: every command goes as Robot Drive's two wheel powers (what a robot's middleware reads);
    #: False: as VIPLE sends it, the Robot+ services as ``servoId`` -1 (the Unity simulator)
    wheels_only: bool = False

    @property
    def name(self) -> str:
        return self.title or (self.definition.name if self.definition else "")

    @property
    def wheels(self) -> WheelPorts:
        if self.ports is not None:
            return self.ports
        return WheelPorts(self.profile.left_port, self.profile.right_port)


def prepare(
    algorithm: str,
    profile: str | None = None,
    params: Sequence[str] = (),
    sensors: Sequence[str] = (),
    connect: str | None = None,
    listen: str | None = None,
    duration: float | None = None,
    unity_simulator: bool = False,
) -> ClientSetup:
    """Check everything the run needs; bad input is a :class:`ClientSetupError`.

    The FSM's commands go as Robot Drive wheel powers, which any robot understands, unless
    ``unity_simulator`` asks for the Unity simulator's Robot+ form (Move at Power, Turn by
    Degree)."""
    if duration is not None and not (math.isfinite(duration) and duration > 0):
        raise ClientSetupError(f"--duration must be a positive number of seconds, not {duration}")
    endpoint = parse_endpoint(connect, listen)
    try:
        prof = get_profile(profile or "unity")
        definition = load_algorithm(algorithm)
        if sensors:
            specs = check_ports(SensorSpec.parse(s) for s in sensors)
        else:
            specs = preset_sensors(definition, prof.name)
        binding = bind_sensors(definition, specs, prof.name)
        overrides = parse_param_overrides(definition, params)
        values = FsmController(definition, overrides, prof.name).params
    except (FsmFileError, FsmError, SensorConfigError, ValueError) as exc:
        raise ClientSetupError(str(exc)) from None
    return ClientSetup(
        definition,
        prof,
        values,
        tuple(specs),
        binding,
        endpoint,
        duration,
        wheels_only=not unity_simulator,
    )


# ----------------------------------------------------------------------------- the FSM side


def turn_wait(degrees: float, profile: Profile) -> float:
    """Seconds after sending Turn by Degree ``degrees`` when the client takes it as done."""
    nominal = abs(degrees) / profile.turn_rate
    return nominal * (1.0 + TURN_MARGIN_FRACTION) + TURN_MARGIN_S


def readings_by_name(
    readings: Mapping[int, SensorValue], binding: Mapping[str, int]
) -> dict[str, float]:
    """A report's readings (port -> value) under the FSM's sensor names, as numbers (numeric
    text converted); a ``CodecError`` for a reading the FSM reads that is not a number."""
    missing = {name: port for name, port in binding.items() if port not in readings}
    if missing:
        wanted = ", ".join(f"port {port} ({name})" for name, port in sorted(missing.items()))
        have = ", ".join(str(p) for p in sorted(readings)) or "none"
        raise ClientRunError(
            f"the reports carry no sensor on {wanted}; they carry port(s) {have}: give both "
            "sides the same sensors (--sensor KIND:PORT:MOUNT on workbench serve and here)"
        )
    return {name: reading_number(readings[port], port) for name, port in binding.items()}


@dataclass(frozen=True)
class Step:
    """What one start or tick did: the commands to send and the transition that fired."""

    t: float
    commands: list[Command]
    transition: Transition | None = None
    turn_done_at: float | None = None
    started: bool = False


class RemoteFsm:
    """The FSM as a VIPLE program runs it: readings by port in, commands out, turn by timer."""

    def __init__(self, setup: ClientSetup) -> None:
        assert setup.definition is not None
        self.setup = setup
        self.controller = FsmController(setup.definition, setup.params, setup.profile.name)
        self.readings: dict[str, float] | None = None
        self.turn_due: float | None = None
        self.last_tick = -math.inf
        self.transitions = 0

    @property
    def state(self) -> str:
        return self.controller.state

    @property
    def timing(self) -> bool:
        return self.turn_due is not None

    def start(self, t: float) -> Step:
        return self._step(t, self.controller.start(t), None, started=True)

    def report(self, t: float, readings: Mapping[int, SensorValue], text: str = "") -> Step:
        """A sensor report arrived: tick with its readings (the FSM reads numbers only)."""
        self.readings = readings_by_name(readings, self.setup.binding)
        return self.tick(t)

    def next_tick(self) -> float:
        """When the next tick is due if no report comes first."""
        return self.last_tick + 1.0 / CONTROL_HZ

    def tick(self, t: float) -> Step:
        """Tick with the latest readings (none yet: nothing happens)."""
        self.last_tick = t
        if self.readings is None:
            return Step(t, [])
        events: frozenset[str] = frozenset()
        if self.turn_due is not None and t >= self.turn_due:
            self.turn_due = None
            events = frozenset({"turn_done"})
        history = self.controller.history
        before = history[-1] if history else None
        commands = self.controller.tick(t, self.readings, events)
        fired = history[-1] if history and history[-1] is not before else None
        if fired is not None:
            self.transitions += 1
        return self._step(t, commands, fired)

    def _step(
        self, t: float, commands: list[Command], fired: Transition | None, started: bool = False
    ) -> Step:
        """Follow the turn in progress: a Turn by Degree starts the wait for its end, any
        other command abandons it (as on the robot)."""
        for cmd in commands:
            self.turn_due = (
                t + turn_wait(cmd.degrees, self.setup.profile)
                if isinstance(cmd, TurnByDegrees)
                else None
            )
        due = self.turn_due if commands and isinstance(commands[-1], TurnByDegrees) else None
        return Step(t, commands, fired, due, started)


# ----------------------------------------------------------------------------- departures


@dataclass
class Departures:
    """When a step's commands leave, so that the time between two commands on the robot is
    never shorter than the time between their steps.

    A step runs at its time ``t`` on the client's clock, but its commands can leave only once
    it has run, ``lag`` later. While a timer runs, each step's commands wait until ``t`` plus
    the largest lag of the steps before them (the first command of a 40 ms pulse left 6 ms
    late: its end leaves 6 ms late too, however quickly its step ran). With no timer running
    nothing spans from earlier commands to later ones, so the lag starts again from zero. A
    lag over :data:`MAX_LAG_S` is a stall of the whole machine (a suspended process), not the
    time a step ran: it is carried only up to that bound."""

    lag: float = 0.0

    def begin(self, timing: bool) -> None:
        """A step is about to run; ``timing``: a timer of the brain was running before it."""
        if not timing:
            self.lag = 0.0

    def due(self, t: float) -> float:
        """When the commands of the step of time ``t`` may leave."""
        return t + self.lag

    def left(self, t: float, now: float) -> None:
        """The commands of the step of time ``t`` leave at ``now``, not held (``now`` is at or
        past their :meth:`due` time)."""
        self.lag = min(max(self.lag, now - t), MAX_LAG_S)


# ----------------------------------------------------------------------------- channels


class Channel(Protocol):
    """One connection to the simulator, TCP or WebSocket."""

    async def send(self, message: str) -> None: ...

    async def receive(self) -> tuple[list[str], list[str]] | None:
        """The next lines and the reasons of dropped ones; None when the connection is gone."""
        ...

    async def close(self) -> None: ...


class TcpChannel:
    def __init__(self, reader: asyncio.StreamReader, writer: asyncio.StreamWriter) -> None:
        self.reader = reader
        self.writer = writer
        self.splitter = LineSplitter()

    async def send(self, message: str) -> None:
        self.writer.write(message.encode("utf-8") + b"\r\n")
        await self.writer.drain()

    async def receive(self) -> tuple[list[str], list[str]] | None:
        try:
            data = await self.reader.read(65536)
        except OSError:
            return None
        if not data:
            return None
        try:
            return self.splitter.feed(data), []
        except FrameError as err:
            return err.lines, err.reasons

    async def close(self) -> None:
        self.writer.close()
        with contextlib.suppress(OSError):
            await self.writer.wait_closed()


class WsChannel:
    def __init__(self, connection: ServerConnection) -> None:
        self.connection = connection

    async def send(self, message: str) -> None:
        await self.connection.send(message)

    async def receive(self) -> tuple[list[str], list[str]] | None:
        try:
            frame = await self.connection.recv()
        except ConnectionClosed:
            return None
        if isinstance(frame, bytes):
            return [], [f"binary frame of {len(frame)} bytes ignored: VIPLE sends text frames"]
        return split_frame(frame), []

    async def close(self) -> None:
        await self.connection.close()


# ----------------------------------------------------------------------------- the run


@dataclass
class ClientResult:
    endpoint: str
    algorithm: str
    profile: str
    #: "duration", "closed", "stopped" (the user's quit key), "interrupted" (a signal),
    #: "error" or "no connection"
    ended: str
    exit_code: int
    time: float = 0.0
    reports: int = 0
    rejected: int = 0
    commands: int = 0
    transitions: int = 0
    final_state: str | None = None
    readings: dict[str, SensorValue] = field(default_factory=dict)
    message: str = ""

    def as_dict(self) -> dict[str, Any]:
        return {
            "endpoint": self.endpoint,
            "algorithm": self.algorithm,
            "profile": self.profile,
            "ended": self.ended,
            "exit_code": self.exit_code,
            "time": round(self.time, 3),
            "reports": self.reports,
            "rejected_reports": self.rejected,
            "commands": self.commands,
            "transitions": self.transitions,
            "final_state": self.final_state,
            "readings": {
                k: round(v, 4) if isinstance(v, float) else v for k, v in self.readings.items()
            },
            "message": self.message,
        }


class _Closed:
    """The connection is gone."""


@dataclass(frozen=True)
class _Interrupted:
    signum: int


@dataclass(frozen=True)
class _Stopped:
    """The user asked to stop (a front end's quit key): the robot stops, the run ends well."""

    message: str


@dataclass(frozen=True)
class _Key:
    key: str


@dataclass(frozen=True)
class _Received:
    lines: list[str]
    problems: list[str]


@dataclass(frozen=True)
class _Connected:
    channel: Channel
    peer: str


class VipleClient:
    """One run: meet the simulator, drive it with the FSM until the run ends."""

    def __init__(
        self,
        setup: ClientSetup,
        log: Callable[[str], None] = print,
        on_step: Callable[[Step, str | None], None] | None = None,
    ) -> None:
        self.setup = setup
        self.log = log
        self.on_step = on_step or (lambda step, state: None)
        self.inbox: asyncio.Queue[object] = asyncio.Queue()
        self.result = ClientResult(str(setup.endpoint), setup.name, setup.profile.name, "", EXIT_OK)
        self._busy = False
        self._released = asyncio.Event()
        self._t0 = 0.0
        self._wheel_drive = WheelDrive(setup.profile) if setup.wheels_only else None
        self._departures = Departures()

    def interrupt(self, signum: int = signal.SIGINT) -> None:
        """Stop the run (from a signal handler): stop the robot, close, summarise."""
        self.inbox.put_nowait(_Interrupted(signum))

    def stop(self, message: str) -> None:
        """Stop the run because the user asked to (exit code 0): stop the robot, close."""
        self.inbox.put_nowait(_Stopped(message))

    def press(self, key: str) -> None:
        """A key typed while driving; it reaches a brain that takes keys (others ignore it,
        as do runs not yet connected)."""
        self.inbox.put_nowait(_Key(key))

    async def run(self) -> ClientResult:
        try:
            if self.setup.endpoint.role == "connect":
                await self._run_connected()
            else:
                await self._run_listening()
        except OSError as exc:
            ep = self.setup.endpoint
            reason = _os_reason(exc)
            if exc.errno == errno.EADDRINUSE:
                reason = f"port {ep.port} is in use: stop the program using it or choose another"
            self._end("no connection", EXIT_FAILED, f"cannot listen at {ep}: {reason}")
        return self.result

    # -- meeting the simulator ----------------------------------------------------------

    async def _run_connected(self) -> None:
        channel = await self._connect()
        if channel is not None:
            await self._drive(channel)

    async def _connect(self) -> TcpChannel | None:
        ep = self.setup.endpoint
        deadline = time.monotonic() + CONNECT_PATIENCE_S
        told = False
        while True:
            try:
                reader, writer = await asyncio.open_connection(ep.host, ep.port)
            except socket.gaierror as exc:
                reason = _os_reason(exc)
                self._end("no connection", EXIT_FAILED, f"cannot find host {ep.host!r}: {reason}")
                return None
            except OSError as exc:
                if time.monotonic() >= deadline:
                    self._end(
                        "no connection",
                        EXIT_FAILED,
                        f"cannot connect to {ep}: {_os_reason(exc)}; start the simulator "
                        f"first (workbench serve --tcp-port {ep.port})",
                    )
                    return None
                if not told:
                    self.log(
                        f"nothing answers at {ep} yet ({_os_reason(exc)}); retrying for "
                        f"{CONNECT_PATIENCE_S:g} s"
                    )
                    told = True
                if await self._interrupted_within(CONNECT_RETRY_S):
                    return None
                continue
            self.log(f"connected to {ep}")
            return TcpChannel(reader, writer)

    async def _run_listening(self) -> None:
        ep = self.setup.endpoint
        async with serve(self._accept, ep.host, ep.port, compression=None, ping_interval=None):
            self.log(
                f"VIPLE WebSocket server listening at {ep}; waiting for the simulator "
                f"(workbench serve --ws-url {ep})"
            )
            while True:
                item = await self.inbox.get()
                if self._ends(item):
                    return
                if isinstance(item, _Connected):
                    self.log(f"the simulator connected from {item.peer}")
                    try:
                        await self._drive(item.channel)
                    finally:
                        self._released.set()
                    return

    async def _accept(self, connection: ServerConnection) -> None:
        if self._busy:
            await connection.close(1013, "this VIPLE stand-in already drives a robot")
            return
        self._busy = True
        peer = _peer(connection.remote_address)
        self.inbox.put_nowait(_Connected(WsChannel(connection), peer))
        await self._released.wait()

    async def _interrupted_within(self, seconds: float) -> bool:
        try:
            async with asyncio.timeout(seconds):
                item = await self.inbox.get()
        except TimeoutError:
            return False
        return self._ends(item)

    # -- driving -------------------------------------------------------------------------

    async def _drive(self, channel: Channel) -> None:
        fsm: Brain = self.setup.brain() if self.setup.brain else RemoteFsm(self.setup)
        self._t0 = time.monotonic()  # the brain is made: its time starts now
        pump = asyncio.create_task(self._pump(channel))
        try:
            self._departures.begin(False)
            await self._send_step(channel, fsm.start(0.0), fsm)
            await self._loop(channel, fsm)
        finally:
            pump.cancel()
            with contextlib.suppress(asyncio.CancelledError):
                await pump
            with contextlib.suppress(OSError, ConnectionClosed):
                await channel.close()
            self.result.time = self._now()
            self.result.final_state = fsm.state
            self.result.transitions = fsm.transitions
            self.result.readings = {str(k): v for k, v in (fsm.readings or {}).items()}

    async def _loop(self, channel: Channel, fsm: Brain) -> None:
        end = self.setup.duration
        while True:
            now = self._now()
            if end is not None and now >= end:
                await self._stop_robot(channel)
                self._end("duration", EXIT_OK, f"--duration {end:g} s has passed")
                return
            wake = min(fsm.next_tick(), self._spin_ends(), math.inf if end is None else end)
            try:
                async with asyncio.timeout(max(0.0, wake - now)):
                    item = await self.inbox.get()
            except TimeoutError:
                now = self._now()
                if self._wheel_drive is not None and self._wheel_drive.spin_over(now):
                    await self._send(channel, [Stop()])
                if now >= fsm.next_tick():
                    self._departures.begin(fsm.timing)
                    await self._send_step(channel, fsm.tick(now), fsm)
                continue
            if isinstance(item, _Received):
                await self._reports(channel, fsm, item)
            elif isinstance(item, _Key):
                if isinstance(fsm, TakesKeys):
                    self._departures.begin(fsm.timing)
                    now = self._now()
                    fsm.type_key(item.key, now)
                    await self._send_step(channel, fsm.tick(now), fsm)
            elif isinstance(item, (_Interrupted, _Stopped)):
                await self._stop_robot(channel)
                self._ends(item)
                return
            elif isinstance(item, _Closed):
                self._closed()
                return

    async def _reports(self, channel: Channel, fsm: Brain, item: _Received) -> None:
        for reason in item.problems:
            self._reject(reason)
        for line in item.lines:
            try:
                readings = parse_report(line)
            except ValueError as err:
                self._reject(_refusal(line) or str(err))
                continue
            self._departures.begin(fsm.timing)
            try:
                step = fsm.report(self._now(), readings, line)
            except CodecError as err:
                self._reject(str(err))
                continue
            except (ClientRunError, FsmRuntimeError) as exc:
                await self._stop_robot(channel)
                raise _Abort(str(exc)) from None
            self.result.reports += 1
            await self._send_step(channel, step, fsm)

    async def _pump(self, channel: Channel) -> None:
        try:
            while (got := await channel.receive()) is not None:
                self.inbox.put_nowait(_Received(*got))
        finally:
            self.inbox.put_nowait(_Closed())

    async def _send_step(self, channel: Channel, step: Step, fsm: Brain) -> None:
        """Send a step's commands at their time (see :class:`Departures`)."""
        commands = self._shown(step, fsm)
        if not commands:
            return
        wait = self._departures.due(step.t) - self._now()
        if wait > 0:
            # held to its time: it leaves as late as the ones before it, the lag stays (the
            # event loop's few tenths of a millisecond past it are not added to every later one)
            await asyncio.sleep(wait)
        else:
            self._departures.left(step.t, self._now())
        await self._send(channel, commands)

    async def _send(self, channel: Channel, commands: list[Command]) -> None:
        wheels = self.setup.wheels
        drive = self._wheel_drive
        for cmd in commands:
            if drive is not None:
                cmd = drive.powers(self._now(), cmd)
            try:
                await channel.send(encode_command(cmd, wheels))
            except (OSError, ConnectionClosed):
                return
            self.result.commands += 1

    def _spin_ends(self) -> float:
        """When the spin of a turn sent as wheel powers is to stop (inf: none is going)."""
        drive = self._wheel_drive
        return math.inf if drive is None or drive.spin_ends is None else drive.spin_ends

    async def _stop_robot(self, channel: Channel) -> None:
        await self._send(channel, [Stop()])

    def _shown(self, step: Step, fsm: Brain) -> list[Command]:
        """Report a start or a state change to ``on_step``; the step's commands."""
        if step.transition is not None or step.started:
            self.on_step(step, fsm.state)
        return step.commands

    # -- ending --------------------------------------------------------------------------

    def _now(self) -> float:
        return time.monotonic() - self._t0

    def _reject(self, reason: str) -> None:
        self.result.rejected += 1
        if self.result.rejected <= SHOWN_REJECTIONS:
            self.log(f"{self._now():8.2f} s  report rejected: {reason}")
        if self.result.rejected == SHOWN_REJECTIONS:
            self.log("further rejected reports are only counted")

    def _closed(self) -> None:
        if self.result.reports:
            self._end("closed", EXIT_OK, "the simulator closed the connection")
        else:
            self._end(
                "closed", EXIT_FAILED, "the simulator closed the connection before any report"
            )

    def _ends(self, item: object) -> bool:
        """End the run if ``item`` asks to (a signal or the user's stop); False otherwise."""
        if isinstance(item, _Interrupted):
            name = signal.Signals(item.signum).name
            self._end("interrupted", 128 + item.signum, f"stopped by {name}")
            return True
        if isinstance(item, _Stopped):
            self._end("stopped", EXIT_OK, item.message)
            return True
        return False

    def _end(self, ended: str, code: int, message: str) -> None:
        self.result.ended = ended
        self.result.exit_code = code
        self.result.message = message


class _Abort(Exception):
    """The run cannot go on (see :class:`ClientRunError`)."""


async def run_client(
    setup: ClientSetup,
    log: Callable[[str], None] = print,
    on_step: Callable[[Step, str | None], None] | None = None,
    attach: Callable[[VipleClient], Callable[[], None]] | None = None,
) -> ClientResult:
    """Run the client until the run ends; SIGINT and SIGTERM end it cleanly.

    ``attach`` hooks a front end to the client before it starts (a live keyboard calls
    :meth:`VipleClient.press` and :meth:`VipleClient.stop`); what it returns unhooks it when
    the run ends, however it ends.
    """
    client = VipleClient(setup, log, on_step)
    loop = asyncio.get_running_loop()
    signals = (signal.SIGINT, signal.SIGTERM)
    for signum in signals:
        loop.add_signal_handler(signum, client.interrupt, signum)
    detach = attach(client) if attach is not None else None
    try:
        return await client.run()
    except _Abort as exc:
        client._end("error", EXIT_FAILED, str(exc))
        return client.result
    finally:
        if detach is not None:
            detach()
        for signum in signals:
            loop.remove_signal_handler(signum)


# ----------------------------------------------------------------------------- helpers


def _refusal(line: str) -> str | None:
    """The text of a ``{"error": ...}`` line (how a busy simulator refuses a client)."""
    try:
        message = json.loads(line)
    except (ValueError, RecursionError):
        return None
    if isinstance(message, dict) and isinstance(message.get("error"), str):
        text = message["error"]
        if not text.isprintable():
            text = json.dumps(text)[1:-1]  # control characters shown escaped, never sent raw
        return f"the simulator says: {text}"
    return None


def _peer(address: Any) -> str:
    if isinstance(address, tuple) and len(address) >= 2:
        host = str(address[0])
        return f"[{host}]:{address[1]}" if ":" in host else f"{host}:{address[1]}"
    return str(address)


def _os_reason(exc: OSError) -> str:
    if isinstance(exc, ConnectionRefusedError):
        return "connection refused, nothing listens there"
    if exc.strerror:
        return exc.strerror[:1].lower() + exc.strerror[1:]
    return str(exc) or type(exc).__name__
