"""One remote VIPLE program bound to a live session: commands in, sensor reports out.

Both connection roles (the TCP server that stands in for the Unity simulator and the
WebSocket client that stands in for the Web Simulator) share this piece. A :class:`Link`
turns the lines it is given into ``session.command(...)`` calls, builds the reports VIPLE
reads, counts what went in and out, and stops the robot when its driver goes.

The robot has one driver. Endpoints that serve the same session share one :class:`Seat`:
whoever holds it drives, anyone else is refused (TCP) or waits (WebSocket).

The simulation is stepped by someone else's timer on the same event loop, so a flood of
commands is handled in bounded batches with a yield to the loop between them.

Reports are never queued behind a peer that does not read: an endpoint writes through an
:class:`Outbox`, and while more than ``SEND_BUFFER_BYTES`` are still waiting for the system to
take them, a new report is dropped (the next one carries fresher readings anyway).

A driver that has sent nothing and taken none of its reports for ``idle_s`` seconds loses the
seat (see :meth:`Link.idle_for`): a VIPLE program that is merely quiet still reads its reports,
so its writes keep going out and it is never dropped.

A link drives through a :class:`Cockpit`: the app's lab station is one (it takes the robot for
the program, runs its clock at 1x while the program is connected, and holds its commands while
paused); a bare :class:`Session` (``workbench serve``) is driven through
:class:`SessionCockpit`.
"""

from __future__ import annotations

import asyncio
import json
import logging
import math
import time
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field, fields
from typing import Protocol

from workbench.sim.commands import Command, Stop
from workbench.sim.driver import NOBODY, Driver

# the report interval's rule, shared with offline program runs (named here for the endpoints)
from workbench.sim.profiles import REPORT_MS_DEFAULT as REPORT_MS_DEFAULT
from workbench.sim.profiles import REPORT_MS_MAX as REPORT_MS_MAX
from workbench.sim.profiles import REPORT_MS_MIN as REPORT_MS_MIN
from workbench.sim.profiles import check_report_ms as check_report_ms
from workbench.sim.session import Session

from .codec import CodecError, WheelPorts, encode_report, parse_command

#: lines (and reads) handled before the loop gets a turn
BATCH = 64
#: bytes of reports an endpoint holds for a peer that is slow to read; above it reports drop
SEND_BUFFER_BYTES = 16384
#: how long a driver may send nothing and read nothing before it loses the seat, seconds
IDLE_S_DEFAULT = 30.0


class Outbox(Protocol):
    """Where an endpoint's reports go: one connection's writing side."""

    def queued(self) -> int:
        """Bytes written that the system has not taken yet (0: everything went out)."""
        ...

    async def write(self, line: str) -> None:
        """Write one message without waiting for the peer to read it."""
        ...


def check_idle_s(value: object) -> float | None:
    """The driver idle time in seconds (None: never), or ``ValueError`` saying what is allowed."""
    if value is None:
        return None
    if isinstance(value, bool) or not isinstance(value, int | float) or not value > 0:
        raise ValueError(f"driver idle time must be a number of seconds above 0, not {value!r}")
    if not math.isfinite(value):
        raise ValueError("driver idle time must be finite; use None for no limit")
    return float(value)


class Cockpit(Protocol):
    """Where a VIPLE program over the network sits to drive: the robot's session, read for
    its profile and readings, and the seat's three moves."""

    @property
    def session(self) -> Session: ...

    def take_seat(self, driver: Driver) -> None:
        """The program ``driver`` connected: it drives from now on."""
        ...

    def leave_seat(self, driver: Driver) -> None:
        """The program ``driver`` went: its motors stop (nothing if it no longer drives)."""
        ...

    def drive(self, cmd: Command, driver: Driver) -> bool:
        """A command of the program's; False when it was held, not applied (paused)."""
        ...


@dataclass
class SessionCockpit:
    """A bare session's seat (``workbench serve``): commands apply at once, time is the
    server's."""

    session: Session

    def take_seat(self, driver: Driver) -> None:
        self.session.detach(driver)  # the program takes over from any controller

    def leave_seat(self, driver: Driver) -> None:
        if self.session.driver == driver:
            self.session.command(Stop(), driver=NOBODY)

    def drive(self, cmd: Command, driver: Driver) -> bool:
        self.session.command(cmd, driver=driver)
        return True


def cockpit_of(robot: Session | Cockpit) -> Cockpit:
    """The seat of ``robot``: a station is its own, a bare session gets one."""
    return SessionCockpit(robot) if isinstance(robot, Session) else robot


@dataclass(frozen=True)
class LinkStatus:
    """What a front end shows about one endpoint."""

    #: "tcp" (Unity-simulator role) or "ws" (Web-Simulator role)
    role: str
    #: where the endpoint listens ("127.0.0.1:1350, [::1]:1350") or what it connects to
    address: str = ""
    #: the connected VIPLE program ("127.0.0.1:50312", "ws://localhost:8124/"), or None
    peer: str | None = None
    messages_in: int = 0
    messages_out: int = 0
    invalid: int = 0
    last_rejection: str | None = None
    #: connections served so far and connections refused because the robot was busy
    connections: int = 0
    refused: int = 0
    #: reports dropped because the program was not reading them
    dropped: int = 0
    #: connections that lost the driver's seat for being idle
    idled: int = 0
    #: commands held, not applied, because the robot's station was paused
    held: int = 0

    @property
    def connected(self) -> bool:
        return self.peer is not None


#: what a status is made of, in its order: the link's attributes of the same names
_STATUS_FIELDS = tuple(f.name for f in fields(LinkStatus))


@dataclass
class Seat:
    """The one driver's seat of a robot, shared by every endpoint serving its session."""

    holder: str | None = None

    def claim(self, who: str) -> bool:
        if self.holder is not None and self.holder != who:
            return False
        self.holder = who
        return True

    def release(self, who: str) -> None:
        if self.holder == who:
            self.holder = None


@dataclass
class RateLimitedLog:
    """Logs at most ``burst`` messages per ``period`` seconds and counts the rest."""

    logger: logging.Logger
    burst: int = 5
    period: float = 10.0
    clock: Callable[[], float] = time.monotonic
    _window_start: float = field(default=-1e18, init=False)
    _in_window: int = field(default=0, init=False)
    _suppressed: int = field(default=0, init=False)

    def warning(self, message: str, *args: object) -> None:
        now = self.clock()
        if now - self._window_start >= self.period:
            self.flush()
            self._window_start = now
            self._in_window = 0
        if self._in_window < self.burst:
            self._in_window += 1
            self.logger.warning(message, *args)
        else:
            self._suppressed += 1

    def flush(self) -> None:
        """Log how many messages were held back, if any."""
        if self._suppressed:
            self.logger.warning(
                "... and %d more invalid messages not logged one by one", self._suppressed
            )
            self._suppressed = 0


class Link:
    """Binds one remote driver at a time to ``session``.

    An endpoint calls :meth:`connect` when a VIPLE program arrives, hands each received line
    to :meth:`handle` with a way to send the reply, sends :meth:`report` on its timer, and
    calls :meth:`disconnect` when the program goes.
    """

    def __init__(
        self,
        robot: Session | Cockpit,
        role: str,
        address: str = "",
        seat: Seat | None = None,
        logger: logging.Logger | None = None,
        batch: int = BATCH,
        idle_s: float | None = IDLE_S_DEFAULT,
    ) -> None:
        if batch < 1:
            raise ValueError(f"batch must be at least 1, not {batch!r}")
        self.idle_s = check_idle_s(idle_s)
        self.cockpit = cockpit_of(robot)
        self.session = self.cockpit.session
        self.seat = seat if seat is not None else Seat()
        self.log = logger or logging.getLogger(f"workbench.viple.{role}")
        self.batch = batch
        self.role = role
        self.address = address
        self.peer: str | None = None
        self.messages_in = 0
        self.messages_out = 0
        self.invalid = 0
        self.last_rejection: str | None = None
        self.connections = 0
        self.refused = 0
        self.dropped = 0
        self.idled = 0
        self.held = 0
        #: the last command was held (the station is paused): said once in the log
        self._holding = False
        self._line_no = 0
        self._active_at = time.monotonic()
        self._driver: Driver | None = None
        self._work = 0
        self._bad_log = RateLimitedLog(self.log)
        #: the last status given, with the values it was made of
        self._status: tuple[tuple[object, ...], LinkStatus] | None = None

    # -- status --------------------------------------------------------------------------
    @property
    def status(self) -> LinkStatus:
        """The endpoint's status at this moment (a snapshot; the same object while nothing in
        it changed, as the app asks for it every tick)."""
        key = tuple(getattr(self, name) for name in _STATUS_FIELDS)
        kept = self._status
        if kept is None or kept[0] != key:
            kept = self._status = (key, LinkStatus(*key))
        return kept[1]

    @property
    def driver(self) -> Driver | None:
        """The session's driver while a program is connected (a VIPLE driver with role and peer)."""
        return self._driver

    @property
    def wheels(self) -> WheelPorts:
        profile = self.session.profile
        return WheelPorts(profile.left_port, profile.right_port)

    # -- who drives ----------------------------------------------------------------------
    def busy_with(self) -> str | None:
        """Who holds the robot's driver seat (any endpoint of this session), else None."""
        return self.seat.holder

    def connect(self, peer: str) -> bool:
        """A VIPLE program at ``peer`` wants to drive; False (and counted) when busy.

        The program takes over from any controller attached to the session.
        """
        if not self.seat.claim(peer):
            self.refuse(peer)
            return False
        self.peer = peer
        self.connections += 1
        self._line_no = 0
        self._driver = Driver.viple(self.role, peer)
        self._bad_log = RateLimitedLog(self.log)
        self._active_at = time.monotonic()
        self._holding = False
        self.cockpit.take_seat(self._driver)
        return True

    def refuse(self, peer: str) -> None:
        self.refused += 1
        self.log.warning(
            "refused %s: %s is already driving this robot", peer, self.seat.holder or "someone"
        )

    def busy_message(self) -> str:
        """The one-line JSON error a refused program gets."""
        holder = self.seat.holder or "another program"
        text = f"busy: another VIPLE program is driving this robot (from {holder})"
        return json.dumps({"error": text}, separators=(",", ":"))

    def disconnect(self, reason: str = "") -> None:
        """The program went: stop the motors (if it still drives) and free the seat."""
        peer = self.peer
        if peer is None:
            return
        self._bad_log.flush()
        self._stop_motors()
        self.seat.release(peer)
        self._driver = None
        self.peer = None
        self.log.info("%s disconnected%s; motors stopped", peer, f" ({reason})" if reason else "")

    def _stop_motors(self) -> None:
        if self._driver is not None:
            self.cockpit.leave_seat(self._driver)

    # -- messages ------------------------------------------------------------------------
    def report(self) -> str:
        """A report carrying every configured sensor, from the session's latest readings."""
        readings = self.session.readings
        kinds = {
            spec.port: spec.kind for spec in self.session.world.sensors if spec.port in readings
        }
        return encode_report({port: readings[port] for port in kinds}, kinds)

    def heard(self) -> None:
        """The program sent something (any bytes, even a line that is then rejected)."""
        self._active_at = time.monotonic()

    def idle_for(self) -> float:
        """Seconds since the program last sent anything or took a report.

        A report counts as taken when, at the time of the next one, everything written before
        has gone out to the system; a program that stops reading fills the socket buffers and
        then its reports stay queued.
        """
        return time.monotonic() - self._active_at

    async def offer(self, outbox: Outbox, line: str) -> bool:
        """Write a report unless the program is too far behind in reading; False if dropped."""
        queued = outbox.queued()
        if queued == 0:
            self._active_at = time.monotonic()
        elif queued > SEND_BUFFER_BYTES:
            self.dropped += 1
            return False
        await outbox.write(line)
        self.messages_out += 1
        return True

    def received(self) -> int:
        """Count a received message; its line number in this connection."""
        self.messages_in += 1
        self._line_no += 1
        return self._line_no

    def reject(self, reason: str, line_no: int | None = None, log: bool = True) -> None:
        """Count a message that was not accepted; log it (rate-limited) unless ``log`` is
        False because the caller logs it itself."""
        if line_no is not None:
            reason = f"line {line_no}: {reason}"
        self.invalid += 1
        self.last_rejection = reason
        if log:
            self._bad_log.warning("%s: rejected %s", self.peer or "VIPLE", reason)

    def apply(self, line: str) -> bool:
        """Apply one command line to the session; False when it was rejected (and counted)."""
        line_no = self.received()
        try:
            commands = parse_command(line, self.wheels)
        except CodecError as err:
            self.reject(str(err), line_no)
            return False
        driver = self._driver or Driver.viple(self.role)
        applied = [self.cockpit.drive(cmd, driver) for cmd in commands]
        self._held_or_applied(len(applied) - sum(applied), line_no)
        if self.log.isEnabledFor(logging.DEBUG):
            self.log.debug("%s: line %d: %s", self.peer or "VIPLE", line_no, commands)
        return True

    def _held_or_applied(self, held: int, line_no: int) -> None:
        """Count the commands the station held (paused); the log says when holding begins
        and ends, not at every line."""
        self.held += held
        who = self.peer or "VIPLE"
        if held and not self._holding:
            self._holding = True
            self.log.warning(
                "%s: line %d: commands held, not applied: the station is paused (the program "
                "still gets the robot's readings)",
                who,
                line_no,
            )
        elif not held and self._holding:
            self._holding = False
            self.log.warning("%s: line %d: commands applied again", who, line_no)

    async def handle(self, lines: Iterable[str], outbox: Outbox) -> None:
        """Apply each line and answer each accepted one with a report, yielding between batches."""
        for line in lines:
            await self.take(line, outbox)

    async def take(self, line: str, outbox: Outbox) -> None:
        """Apply one line, answer it with a report when it was accepted, and pace."""
        if self.apply(line):
            await self.offer(outbox, self.report())
        await self.pace()

    async def pace(self, work: int = 1) -> None:
        """Count ``work`` units; every ``batch`` units the event loop gets a turn."""
        self._work += work
        if self._work >= self.batch:
            self._work = 0
            await asyncio.sleep(0)

    async def push_reports(self, outbox: Outbox, interval: float) -> str:
        """Send a report now and then every ``interval`` seconds, until cancelled or until the
        driver has been idle for ``idle_s``: then the reason it loses the seat is returned.

        The schedule follows the loop's clock; reports missed while the loop was busy are
        skipped, not sent in a burst.
        """
        loop = asyncio.get_running_loop()
        due = loop.time()
        while True:
            await self.offer(outbox, self.report())
            if self.idle_s is not None and self.idle_for() >= self.idle_s:
                self._stop_motors()  # at once: the connection may take a while to close
                self.idled += 1
                return (
                    f"idle: sent nothing and read no reports for {self.idle_s:g} s; "
                    "the seat is free again"
                )
            due += interval
            now = loop.time()
            if due < now:
                due = now + interval - (now - due) % interval
            await asyncio.sleep(due - now)
