"""The live workbench: one maze, one robot, who drives it, and the runs done so far.

Everything the app shows and every action it offers goes through :class:`LabStation`, so the app
only renders and routes input. A station owns a :class:`Session` and its :class:`Pacer`.
"""

from __future__ import annotations

import os
import secrets
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any

from workbench.files.workspace import LOCAL, FileAccess
from workbench.fsm.algorithms import load_algorithm
from workbench.fsm.machine import (
    FsmController,
    FsmDefinition,
    FsmRuntimeError,
    bind_sensors,
    preset_sensors,
)
from workbench.fsm.yaml_file import parse_param_overrides
from workbench.sim.clock import Pacer
from workbench.sim.commands import Command, MotorPower, Stop, motion_of
from workbench.sim.driver import BY_KEYS, NOBODY, Driver
from workbench.sim.maze import Maze
from workbench.sim.metrics import Metrics
from workbench.sim.noise import NoiseSettings
from workbench.sim.profiles import get_profile
from workbench.sim.record import RecordStop
from workbench.sim.sensor_kinds import KINDS, PANEL_KINDS, sensor_kind
from workbench.sim.sensors import (
    MOUNTS,
    PORT_RANGE,
    SensorConfigError,
    SensorSpec,
    check_ports,
)
from workbench.sim.session import Session, Snapshot

from .driving import Driving, algorithm_driving, record_fields
from .lifecycle import ERROR, EXIT, MAZE_CHANGED, RESET, STOPPED, Run, ending
from .manual import exact_move, key_command
from .recording import RecordQuota, RecordTrouble, record_stopped

#: the sensor presets of the course's simulators (Web Simulator panel, Unity simulator)
PRESETS: dict[str, tuple[SensorSpec, ...]] = {
    "unity": (SensorSpec("distance", 1, "right"), SensorSpec("distance", 2, "front")),
    "web-wall-following": (SensorSpec("distance", 1, "right"), SensorSpec("touch", 2, "front")),
    "web-two-distance": (SensorSpec("distance", 3, "front"),),
}


@dataclass(frozen=True)
class SensorRow:
    """One row of the sensor port panel as typed: kind, port text, mount (None = not mounted)."""

    kind: str
    port: str
    mount: str | None


@dataclass(frozen=True)
class RunEntry:
    """A finished (or abandoned) run, for comparing algorithms side by side."""

    number: int
    driver: Driver
    maze: str
    profile: str
    seed: int
    metrics: Metrics
    #: how it ended: EXIT, STOPPED, RESET, MAZE_CHANGED or ERROR (:mod:`.lifecycle`)
    ended: str
    record: str | None = None
    #: the FSM file of the algorithm, or the program file, that drove (None for keys and VIPLE)
    source: str | None = None
    #: the layout digest of the maze the run was on (see ``Maze.digest``)
    maze_digest: str = ""
    #: the id of the lab exercise's attempt that was under way when the run began ("" none)
    attempt: str = ""
    #: who of the pair was at the station when the run began ("" nobody named)
    person: str = ""
    #: every sensor the robot carried during the run, sorted by their text: the ones it
    #: began with and any fitted while it went on (a run on changed sensors carries both)
    sensors: tuple[SensorSpec, ...] = ()
    #: the program file or FSM file that drove, its digest, and the file that comes with
    #: the workbench that it is ("" for none; see ``Driving``)
    program_name: str = ""
    program_sha256: str = ""
    bundled: str = ""

    @property
    def moved(self) -> bool:
        """The robot went somewhere or turned during the run."""
        return self.metrics.distance > 0 or self.metrics.turn_degrees > 0


#: how a run still under way is ended in :meth:`LabStation.run_so_far`
UNDER_WAY = "under way"


@dataclass(frozen=True)
class Attempt:
    """One go at a lab exercise, begun by its set-up: the work done on the station while it
    is the current attempt (runs, edits, keys, VIPLE programs) is that exercise's work."""

    #: unique on the station (and beyond: random), kept with the work and its evidence
    id: str
    lab: str
    exercise: str
    #: the exercise's profile, and who of the pair was at the station, at the set-up
    profile: str
    person: str = ""


@dataclass(frozen=True)
class MazeEdit:
    """A maze edited in the editor and put on the station (loading a maze is not an edit)."""

    number: int
    #: the maze as edited (its name and layout digest), and the one the editor opened
    maze: str
    maze_digest: str
    opened_digest: str
    #: the maze has no problems (see ``Maze.validate``)
    valid: bool
    attempt: str = ""
    person: str = ""
    #: the blocks added or removed by hand in the editor (what Generate, New or loading
    #: made, and edits undone, are not counted)
    hand_blocks: int = 0


@dataclass(frozen=True)
class KeyUse:
    """A drive key pressed on the station: in which attempt, on which profile, by whom."""

    key: str
    attempt: str
    profile: str
    person: str = ""


#: the kinds of :class:`Notice`
ALGORITHM_FAILED = "algorithm failed"
#: a program stopped itself past its limits (detail: when, where and why)
PROGRAM_STOPPED = "program stopped"
OUT = "out"
RECORDING = "recording"


@dataclass(frozen=True)
class Notice:
    """Something the station did on its own (not asked by a key or a button): a front end
    words it for the person at the station. A new value each time, so it can be told apart
    from the last one seen."""

    kind: str  # ALGORITHM_FAILED, PROGRAM_STOPPED (detail: why), OUT (at the exit), RECORDING
    detail: str = ""
    #: RECORDING: why the run goes unrecorded, or what was done to record it
    recording: RecordTrouble | None = None


@dataclass(frozen=True)
class ProgramChoice:
    """A program file chosen to drive, read and checked by the layer that knows programs."""

    #: the file's name, as the driver and the runs show it
    name: str
    #: the path it was read from, and sha256 of its bytes
    source: str
    digest: str
    #: the program driving afresh, from its start, its sensors reported every so many
    #: milliseconds
    make: Callable[[int], Driving]
    #: why the program cannot run with these sensors (None when it can)
    needs: Callable[[Sequence[SensorSpec]], str | None]
    #: a few lines on what the program is and what it answers (keys, sensors)
    summary: tuple[str, ...] = ()
    #: the robot's sensors changed to the ones the program reads (its ports and kinds), and
    #: what cannot be fitted (None when all can)
    fit: Callable[[Sequence[SensorSpec]], tuple[list[SensorSpec], str | None]] | None = None


@dataclass
class VipleConnection:
    """A VIPLE program that held the robot: its role (tcp / ws), where it was, what it did."""

    role: str
    peer: str
    #: distance travelled and degrees turned while it drove, in the profile's units
    distance: float = 0.0
    turn_degrees: float = 0.0
    #: the motions its commands asked for, named as the drive keys' (forward, left, ...)
    motions: set[str] = field(default_factory=set)
    #: the attempt under way, the profile and who of the pair was at the station when it
    #: took the robot (or when that attempt began)
    attempt: str = ""
    profile: str = ""
    person: str = ""

    @property
    def drove(self) -> bool:
        return self.distance > 0 or self.turn_degrees > 0


def check_sensor_rows(rows: Sequence[SensorRow]) -> tuple[list[SensorSpec], dict[int, str]]:
    """The specs for the mounted rows, and an error per row index (empty when all is well)."""
    specs: list[SensorSpec] = []
    errors: dict[int, str] = {}
    owner: dict[int, int] = {}
    for i, row in enumerate(rows):
        if row.mount is None:
            continue
        text = row.port.strip()
        if not text.lstrip("-").isdigit():
            errors[i] = f"port {text!r} is not a whole number"
            continue
        port = int(text)
        if port not in PORT_RANGE:
            errors[i] = f"port {port} is out of range ({PORT_RANGE.start}-{PORT_RANGE.stop - 1})"
            continue
        if row.kind not in KINDS:
            errors[i] = f"unknown kind {row.kind!r}"
            continue
        if row.mount not in MOUNTS:
            errors[i] = f"unknown mount {row.mount!r}"
            continue
        if row.mount not in sensor_kind(row.kind).mounts:
            errors[i] = f"a {row.kind} sensor cannot be mounted {row.mount}"
            continue
        if port in owner:
            errors[i] = f"port {port} is already used by row {owner[port] + 1}"
            errors.setdefault(owner[port], f"port {port} is also used by row {i + 1}")
            continue
        owner[port] = i
        specs.append(SensorSpec(row.kind, port, row.mount))
    return specs, errors


@dataclass
class LabStation:
    maze: Maze
    profile: str
    sensors: list[SensorSpec]
    seed: int = 0
    noise: NoiseSettings | str | None = None
    record_dir: str | None = None
    #: how much room the run records may take (:mod:`.recording`)
    record_quota: RecordQuota = field(default_factory=RecordQuota)
    #: which files the student may open (all of them, unless served in a workspace)
    files: FileAccess = LOCAL
    session: Session = field(init=False)
    pacer: Pacer = field(init=False)
    #: the algorithm chosen, and the parameters edited for it
    algorithm: FsmDefinition | None = None
    overrides: dict[str, float] = field(default_factory=dict)
    runs: list[RunEntry] = field(default_factory=list)
    #: every drive key pressed, with its attempt, profile and person (once each)
    key_uses: set[KeyUse] = field(default_factory=set)
    #: every maze edited in the editor and put on the station, oldest first
    edits: list[MazeEdit] = field(default_factory=list)
    #: the lab exercise attempt under way (None: no exercise set up), and every one begun
    attempt: Attempt | None = None
    attempts: list[Attempt] = field(default_factory=list)
    #: who of the pair is at the station now (the work done is recorded as theirs)
    person: str = ""
    #: the last thing the station did on its own that the person at it should hear of
    notice: Notice | None = None
    #: every VIPLE program seen driving this station, oldest first
    viple: list[VipleConnection] = field(default_factory=list)
    #: the TCP port this station's VIPLE endpoint listens on, as its screen shows it (None:
    #: not listening); a lab question about the port also accepts it
    tcp_port: int | None = None
    #: the program file chosen to drive (most recent choice wins over :attr:`algorithm`)
    program: ProgramChoice | None = None
    #: how often a program file driving gets its sensor reports, milliseconds (None: the
    #: profile's simulator period)
    report_ms: int | None = None
    #: what drives the robot now: the chosen algorithm or program, from :meth:`start` until
    #: :meth:`stop` (None while the keys or a VIPLE program over the network drive)
    driving: Driving | None = None
    #: called just before a command from outside (a drive key, a VIPLE program) changes the
    #: robot: a front end that advances time in larger steps while the station is at rest
    #: (see :attr:`at_rest`) brings the clock up to now first
    on_activity: Callable[[], None] | None = None
    #: the VIPLE program over the network that holds the robot's seat (connected through
    #: :meth:`take_seat`), else None: while one does, the clock runs at 1x (its Timers count
    #: wall time) and the speed is held
    live_viple: Driver | None = None
    #: commands the live VIPLE program sent while the station was paused (held, not applied)
    held_count: int = 0
    _held: list[Command] = field(default_factory=list)
    _run_driver: Driver = BY_KEYS
    _run_source: str | None = None
    _run_attempt: str = ""
    _run_person: str = ""
    #: the sensors the run under way has carried so far, by their text
    _run_sensors: dict[str, SensorSpec] = field(default_factory=dict)
    #: the program that drives the run under way: its name, digest and what it is if bundled
    _run_program: tuple[str, str, str] = ("", "", "")
    _viple_now: VipleConnection | None = None
    #: the odometry (distance, degrees) last counted into :attr:`_viple_now`
    _viple_mark: tuple[float, float] = (0.0, 0.0)
    #: the run under way (its record, how it ends: :mod:`.lifecycle`), None between runs
    _run: Run | None = None
    #: paused because the robot got out: the next drive, reset, start or maze goes on
    _held_at_exit: bool = False

    @classmethod
    def open(
        cls,
        maze: Maze,
        profile: str | None = None,
        sensors: Sequence[SensorSpec] | None = None,
        **kwargs: Any,
    ) -> LabStation:
        name = profile or maze.profile or "unity"
        chosen = list(sensors) if sensors is not None else list(get_profile(name).sensors)
        return cls(maze=maze, profile=name, sensors=check_ports(chosen), **kwargs)

    def __post_init__(self) -> None:
        # one session for the station's whole life: a new maze goes into it (see load_maze), so
        # the VIPLE endpoints serving it and the pacer keep the one reference
        self.session = Session(self.maze, self.profile, self.sensors, self.noise, self.seed)
        self.pacer = Pacer(self.session)
        self.session.driver = BY_KEYS

    # -- time ----------------------------------------------------------------------------
    def advance(self, wall_seconds: float, lag: float | None = None) -> int:
        """Run real time forward; closes the run when the robot gets out.

        ``lag`` is the most wall time owed that is kept (the pacer's ``max_lag`` if None).
        An algorithm whose guard or action fails is stopped with the reason in :attr:`notice`
        and the simulation paused, so a front end never sees the exception.
        """
        try:
            steps = self.pacer.advance(wall_seconds, lag)
        except FsmRuntimeError as exc:
            self._algorithm_failed(exc)
            return 0
        self._after_steps()
        return steps

    def step(self, steps: int = 1) -> None:
        """Exactly ``steps`` physics steps (pause + single step, tests, snapshots); the commands
        a live VIPLE program sent while paused apply first (time runs for these steps), unless
        the robot stands at the exit of the run that ended."""
        if self._held_at_exit:
            self._drop_held()
        self._release_held()
        try:
            self.pacer.single_step(steps)
        except FsmRuntimeError as exc:
            self._algorithm_failed(exc)
            return
        self._after_steps()

    @property
    def idle(self) -> bool:
        """True while time changes nothing on the station but the clock: the robot stands with
        its motors off, and no algorithm, program file or live VIPLE program drives it."""
        return self.session.still and self.live_viple is None

    @property
    def at_rest(self) -> bool:
        """True while time changes nothing that can be seen until someone acts: paused, or (at
        a set speed) the robot standing to the eye (:attr:`Session.settled`: :attr:`idle`, or
        stopped against a wall and creeping off it by less than a billionth of a block a
        step) with nobody driving it. Stepping then gives the same run however seldom a front
        end ticks: every step owed is still taken."""
        if self.pacer.paused:
            return True
        return self.pacer.speed is not None and self.live_viple is None and self.session.settled

    # -- speed ---------------------------------------------------------------------------
    def set_speed(self, speed: float | None) -> bool:
        """Run at ``speed`` (one of the pacer's speeds); False (and 1x kept) while a live VIPLE
        program holds the robot: its Timers count wall time, so its simulation runs at 1x."""
        if self.live_viple is not None:
            self.pacer.set_speed(1.0)
            return speed == 1.0
        self.pacer.set_speed(speed)
        return True

    def next_speed(self) -> bool:
        """The next speed of the cycle (1x, 2x, 4x, 10x, max); False, and nothing changed,
        while the speed is held at 1x for a live VIPLE program (:attr:`live_viple`)."""
        if self.live_viple is not None:
            return False
        self.pacer.next_speed()
        return True

    def _activity(self) -> None:
        if self.on_activity is not None:
            self.on_activity()

    def _algorithm_failed(self, exc: FsmRuntimeError) -> None:
        self.stop(ERROR)
        self.pause()
        self.notice = Notice(ALGORITHM_FAILED, str(exc))

    def _after_steps(self) -> None:
        self._count_viple()
        over = ending(self.session, self.driving)
        if over is not None and over.kind == ERROR:
            self.stop(ERROR)
            self.pause()
            self.notice = Notice(PROGRAM_STOPPED, over.detail)
        run = self._run
        stop = run.watch() if run is not None else None
        if stop is not None:
            self._tell_record_stopped(stop)  # the run goes on unrecorded
        if self._run is not None and over is not None and over.kind == EXIT:
            self._close_run(EXIT)
            self.pause()
            self._held_at_exit = True
            self.notice = Notice(OUT)

    def _count_viple(self) -> None:
        """The distance and degrees of the steps just run go to the VIPLE program driving."""
        now = self._viple_now
        if now is None or not self._viple_drives(now):
            return
        odometry = self.session.world.odometry
        seen = (odometry.distance, odometry.turn_degrees)
        last = self._viple_mark
        self._viple_mark = seen
        now.distance += seen[0] - last[0]
        now.turn_degrees += seen[1] - last[1]

    def _viple_drives(self, connection: VipleConnection) -> bool:
        driver = self.session.driver
        return driver.is_viple and (driver.role, driver.peer) == (connection.role, connection.peer)

    # -- the VIPLE seat ------------------------------------------------------------------
    def take_seat(self, driver: Driver) -> None:
        """A VIPLE program over the network connected as ``driver`` (a VIPLE driver with role
        and peer): it takes the robot from whatever drove it, its driving is a run, and until
        :meth:`leave_seat` the clock runs at 1x (its Timers count wall time)."""
        self._activity()
        self.live_viple = driver
        self._drop_held()
        self._viple_takes(driver)
        self.pacer.set_speed(1.0)

    def leave_seat(self, driver: Driver) -> None:
        """The VIPLE program ``driver`` went (or lost the seat): the motors stop, its run ends,
        and the speed is 1x, as after every run (nothing when it does not hold the seat)."""
        if driver != self.live_viple:
            return
        self._activity()
        self.live_viple = None
        self._drop_held()
        if self.session.driver == driver:
            self.session.command(Stop(), driver=NOBODY)
        if self._run_open and self._run_driver == driver:
            self._close_run(STOPPED)
        self.pacer.set_speed(1.0)

    def drive(self, cmd: Command, driver: Driver) -> bool:
        """A motor command from the VIPLE program ``driver``; it takes the robot back from
        the keys or an algorithm that had it. While the station is paused the command is held,
        not applied (False): the robot stands as time does, and the last commands held go to
        the motors when time runs again (:meth:`pause`)."""
        if driver != self.live_viple:
            return True  # it lost the seat (cut off as idle, its connection closing): dropped
        self._activity()
        if self.pacer.paused:
            self._hold(cmd)
            return False
        self._apply_viple(cmd, driver)
        return True

    def _apply_viple(self, cmd: Command, driver: Driver) -> None:
        if self.session.driver != driver or self.driving is not None:
            self._viple_takes(driver)
        self.session.command(cmd, driver=driver)
        motion = motion_of(cmd)
        if motion is not None and self._viple_now is not None:
            self._viple_now.motions.add(motion)

    def _viple_takes(self, driver: Driver) -> None:
        """The VIPLE program ``driver`` drives from now on: what drove lets go (its run ends),
        the program's driving is a run of its own, and it is seen as a connection."""
        self.stop(STOPPED)  # takes the robot from the algorithm or the program file
        if self._run_open and self._run_driver != driver:
            self._close_run(STOPPED)
        self.session.detach(driver)
        self._viple_now = self._connection(driver.role, driver.peer)
        self.viple.append(self._viple_now)
        odometry = self.session.world.odometry
        self._viple_mark = (odometry.distance, odometry.turn_degrees)
        if not self._run_open and not self.session.reached_exit:
            self._open_run(driver)

    def _hold(self, cmd: Command) -> None:
        """Keep a command sent while paused, with those it does not override: a one-wheel
        power keeps the other wheel's, every other command sets both wheels."""
        self.held_count += 1
        if isinstance(cmd, MotorPower):
            self._held = [
                c for c in self._held if not (isinstance(c, MotorPower) and c.wheel == cmd.wheel)
            ]
        else:
            self._held = []
        self._held.append(cmd)

    def _drop_held(self) -> None:
        self._held = []
        self.held_count = 0

    def _release_held(self) -> None:
        """Time runs again: the commands held while paused go to the motors, as the live VIPLE
        program last asked."""
        held, driver = self._held, self.live_viple
        self._drop_held()
        if driver is not None:
            for cmd in held:
                self._apply_viple(cmd, driver)

    def _connection(self, role: str, peer: str) -> VipleConnection:
        attempt = self.attempt.id if self.attempt is not None else ""
        return VipleConnection(
            role, peer, attempt=attempt, profile=self.profile, person=self.person
        )

    @property
    def attempt_id(self) -> str:
        return self.attempt.id if self.attempt is not None else ""

    def begin_attempt(self, lab: str, exercise: str) -> Attempt:
        """A lab exercise starts afresh (its set-up): the work done from now on is this
        attempt's; a VIPLE program driving right now counts from here on."""
        attempt = Attempt(secrets.token_hex(8), lab, exercise, self.profile, self.person)
        self.attempt = attempt
        self.attempts.append(attempt)
        now = self._viple_now
        if now is not None and self._viple_drives(now):
            self._viple_now = self._connection(now.role, now.peer)
            self.viple.append(self._viple_now)
        return attempt

    @property
    def keys_used(self) -> set[str]:
        """The drive keys pressed in the attempt under way (since the station opened when no
        exercise was set up), on any profile."""
        attempt = self.attempt_id
        return {use.key for use in self.key_uses if use.attempt == attempt}

    @property
    def paused(self) -> bool:
        return self.pacer.paused

    def pause(self, paused: bool = True) -> None:
        """Stop simulated time (or, with False, let it run again): the user's choice. When
        time runs again, the commands a live VIPLE program sent meanwhile are applied."""
        if self._held_at_exit:
            self._drop_held()  # sent to a robot standing at the exit: not for what comes next
        self._held_at_exit = False
        was = self.pacer.paused
        self.pacer.paused = paused
        if was and not paused:
            self._release_held()

    def toggle_pause(self) -> bool:
        self.pause(not self.pacer.paused)
        return self.pacer.paused

    def _go_on_after_exit(self) -> None:
        """The run that ended at the exit paused the robot; a new action lets time run again
        (keys would otherwise seem dead after a run)."""
        if self._held_at_exit:
            self.pause(False)  # (which drops what was held for the robot at the exit)

    def snapshot(self) -> Snapshot:
        return self.session.snapshot()

    # -- driving by keys -----------------------------------------------------------------
    def key(self, key: str) -> bool:
        """A drive key (w a s d space); takes the robot from an algorithm. False if no drive key.

        While a program file drives, every key but space goes to the program (its Key Press
        events); space stops the program, as it stops the robot.
        """
        if self.program_drives:
            if key == "space":
                self.stop(STOPPED)
            else:
                self.type_to_program(key)
            return True
        cmd = key_command(self.profile, key)
        if cmd is None:
            return False
        self._activity()
        self._go_on_after_exit()
        self.stop(STOPPED)
        if self._run_open and self._run_driver != BY_KEYS:
            self._close_run(STOPPED)  # the keys take the robot from a VIPLE program
        self._drop_held()  # ... and from what it sent while paused
        if not self._run_open and not self.session.reached_exit:
            self._open_run(BY_KEYS)  # a run starts at the robot's last reset
        self.key_uses.add(KeyUse(key, self.attempt_id, self.profile, self.person))
        self.session.command(cmd, driver=BY_KEYS)
        if exact_move(self.profile, key):
            profile = get_profile(self.profile)
            self.session.command_after(self.session.world.cell / profile.move_speed, Stop())
        return True

    @property
    def program_drives(self) -> bool:
        """True while a program file drives: it answers typed keys (its Key Press events)."""
        return self.driving is not None and self.driving.type_key is not None

    def type_to_program(self, key: str) -> bool:
        """Any key (space too) for the running program's Key Press events, at the simulated
        time; False when no program drives."""
        if self.driving is None or self.driving.type_key is None:
            return False
        self.driving.type_key(key, self.session.world.time)
        return True

    # -- sensors -------------------------------------------------------------------------
    def sensor_rows(self) -> list[SensorRow]:
        """The live sensors as panel rows, padded like the Web Simulator's panel.

        The panel always offers the rows of ``PANEL_KINDS`` (two distance sensors and one
        touch sensor, as the sensor kinds' table says): kinds the robot lacks are added
        unmounted, each on the lowest port no other row uses.
        """
        rows = [SensorRow(s.kind, str(s.port), s.mount) for s in self.sensors]
        used = {s.port for s in self.sensors}
        missing = list(PANEL_KINDS)
        for spec in self.sensors:
            if spec.kind in missing:
                missing.remove(spec.kind)
        for kind in missing:
            port = next(p for p in PORT_RANGE if p not in used and p > 0)
            used.add(port)
            rows.append(SensorRow(kind, str(port), None))
        return rows

    def apply_sensor_rows(self, rows: Sequence[SensorRow]) -> dict[int, str]:
        """Apply the panel's rows to the live robot, or nothing at all when a row is wrong."""
        specs, errors = check_sensor_rows(rows)
        if errors:
            return errors
        self.apply_sensors(specs)
        return {}

    def apply_sensors(self, specs: Sequence[SensorSpec]) -> None:
        specs = check_ports(specs)
        self.session.set_sensors(specs)
        self.sensors = list(specs)
        if self._run_open:
            self._run_sensors.update((str(spec), spec) for spec in specs)
        if self.driving is not None:
            self.session.binding = self.driving.bind(specs)

    def apply_preset(self, name: str) -> None:
        try:
            self.apply_sensors(PRESETS[name])
        except KeyError:
            raise SensorConfigError(
                f"unknown preset {name!r}: use one of {', '.join(PRESETS)}"
            ) from None

    # -- algorithms ----------------------------------------------------------------------
    def select_algorithm(self, name_or_path: str | os.PathLike) -> FsmDefinition:
        """Choose an algorithm (built-in name or YAML file); errors name the line and fix.

        A file must be one the student may read (:class:`OutsideWorkspace` otherwise).
        """
        return self.use_algorithm(load_algorithm(name_or_path, self.files.for_reading))

    def use_algorithm(self, definition: FsmDefinition) -> FsmDefinition:
        """Choose an algorithm already read (a lab's starter as the lab was loaded)."""
        self.stop(STOPPED)
        self.algorithm = definition
        self.program = None
        self.overrides = {}
        return definition

    def clear_algorithm(self) -> None:
        """No algorithm chosen (the keys drive), and no parameters of one kept."""
        self.stop(STOPPED)
        self.algorithm = None
        self.overrides = {}

    def set_params(self, items: Sequence[str]) -> dict[str, float]:
        """``NAME=VALUE`` edits, all checked before any is kept; returns the values in force."""
        if self.algorithm is None:
            raise ValueError("choose an algorithm first")
        values = parse_param_overrides(self.algorithm, items)
        FsmController(self.algorithm, {**self.overrides, **values}, self.profile)
        self.overrides.update(values)
        return self.params()

    def reset_params(self) -> None:
        self.overrides = {}

    def params(self) -> dict[str, float]:
        if self.algorithm is None:
            return {}
        return FsmController(self.algorithm, self.overrides, self.profile).params

    def missing_sensors(self) -> str | None:
        """Why the chosen algorithm cannot run with the current sensors (None if it can)."""
        if self.algorithm is None:
            return None
        try:
            bind_sensors(self.algorithm, self.sensors, self.profile)
        except ValueError as exc:
            return str(exc)
        return None

    def apply_algorithm_preset(self) -> None:
        """The one-key fix: give the robot the sensors the chosen algorithm needs."""
        if self.algorithm is not None:
            self.apply_sensors(preset_sensors(self.algorithm, self.profile))

    # -- program files -------------------------------------------------------------------
    def use_program(self, choice: ProgramChoice) -> None:
        """Choose a program file to drive (the choice of algorithm is kept for later)."""
        self.stop(STOPPED)
        self.program = choice

    @property
    def program_report_ms(self) -> int:
        """The milliseconds between two sensor reports to a program file driving here."""
        return self.report_ms if self.report_ms is not None else get_profile(self.profile).report_ms

    # -- driving -------------------------------------------------------------------------
    def start(self) -> None:
        """Robot back to the start and the chosen program, else the chosen algorithm, driving
        (a new run). A ``ValueError`` when nothing is chosen or the robot lacks a sensor it
        reads (nothing changes then)."""
        choice = self.program
        if choice is not None:
            missing = choice.needs(self.sensors)
            if missing:
                raise ValueError(missing)
            driving = choice.make(self.program_report_ms)
        elif self.algorithm is not None:
            driving = algorithm_driving(self.algorithm, self.overrides, self.profile)
        else:
            raise ValueError("choose an algorithm first")
        binding = driving.bind(self.sensors)
        speed = self.pacer.speed  # chosen for this run: the run before ends at 1x
        self._drop_held()
        self.stop(STOPPED)
        if self._run_open:
            self._close_run(STOPPED)
        self._go_on_after_exit()
        self.session.reset()
        self.driving = driving
        self.session.attach(driving.controller, binding, driving.driver)
        self._open_run(driving.driver)
        self.set_speed(speed)
        self.pause(False)

    def stop(self, ended: str = STOPPED) -> None:
        """What drives lets go of the robot, which stops; the keys drive (nothing when the
        keys or a VIPLE program over the network drive)."""
        if self.driving is None:
            return
        self.session.command(Stop())
        self.session.detach(BY_KEYS)
        self.driving = None
        if self._run_open:
            self._close_run(ended)

    # -- maze and robot ------------------------------------------------------------------
    def reset_robot(self) -> None:
        """Like the Unity simulator's reset button: the robot back at the start, stopped."""
        self._go_on_after_exit()
        if self._run_open:
            self._close_run(RESET)
        self.stop(RESET)
        self._drop_held()
        self.session.reset()
        self.session.driver = BY_KEYS
        self.pacer.set_speed(1.0)  # a run from the start begins at 1x

    def put_edited_maze(self, maze: Maze, opened: Maze, *, hand_blocks: int) -> MazeEdit:
        """Put a maze edited in the editor on the station (``opened``: the maze the editor
        began with; ``hand_blocks``: how many blocks the student added or removed by hand, as
        the editor counts them), and keep the edit with the attempt under way."""
        edit = MazeEdit(
            number=len(self.edits) + 1,
            maze=maze.name,
            maze_digest=maze.digest(),
            opened_digest=opened.digest(),
            valid=not maze.validate(),
            attempt=self.attempt_id,
            person=self.person,
            hand_blocks=hand_blocks,
        )
        self.edits.append(edit)
        self.load_maze(maze)
        return edit

    def load_maze(self, maze: Maze) -> None:
        """Put a (new or edited) maze on the station; the robot starts over on it."""
        self._go_on_after_exit()
        if self._run_open:
            self._close_run(MAZE_CHANGED)
        self.stop(MAZE_CHANGED)
        self._drop_held()
        self.pacer.set_speed(1.0)
        self.maze = maze
        self.session.load_maze(maze, self.profile, self.sensors, self.noise, self.seed)
        self.session.driver = BY_KEYS

    # -- runs ----------------------------------------------------------------------------
    @property
    def _run_open(self) -> bool:
        return self._run is not None

    def _open_run(self, driver: Driver) -> None:
        self._run_driver = driver
        self._run_source = self.driving.source if self.driving is not None else None
        driving = self.driving
        self._run_program = (
            (driving.program_name, driving.program_sha256, driving.bundled)
            if driving is not None
            else ("", "", "")
        )
        self._run_attempt = self.attempt_id
        self._run_person = self.person
        self._run_sensors = {str(spec): spec for spec in self.sensors}
        person = {"person": self.person} if self.person else {}
        self._run, trouble = Run.in_folder(
            self.session,
            self.record_dir,
            f"run-{len(self.runs) + 1:03d}.jsonl",
            self.record_quota,
            self.files.workspace,
            **record_fields(driver, self.driving),
            **person,
        )
        if trouble is not None:
            self._recording_trouble(trouble)

    def _tell_record_stopped(self, stop: RecordStop) -> None:
        run = self._run
        path = run.path if run is not None else None
        self._recording_trouble(record_stopped(str(path), stop))

    def _recording_trouble(self, trouble: RecordTrouble) -> None:
        self.notice = Notice(RECORDING, trouble.detail, trouble)

    def _close_run(self, ended: str) -> None:
        """The run ends: it is kept (and its record closed), and the speed is 1x again (a
        speed chosen for one run does not carry into the next)."""
        run = self._run
        assert run is not None
        self.pacer.set_speed(1.0)
        if ended == EXIT:  # the run is over as a headless one ends: same numbers, same record
            self.session.settle()
        self.runs.append(self._entry(ended))
        driving = self.driving
        stop = run.end(
            ended=ended, final_state=driving.controller.state if driving is not None else None
        )
        if stop is not None:
            self._tell_record_stopped(stop)
        self._run = None

    def _entry(self, ended: str) -> RunEntry:
        """The run under way as a run entry, ended as ``ended``."""
        name, digest, bundled = self._run_program
        return RunEntry(
            number=len(self.runs) + 1,
            driver=self._run_driver,
            maze=self.maze.name,
            profile=self.profile,
            seed=self.seed,
            metrics=self.session.metrics(),
            ended=ended,
            record=self._run.path if self._run is not None else None,
            source=self._run_source,
            maze_digest=self.maze.digest(),
            attempt=self._run_attempt,
            person=self._run_person,
            sensors=tuple(spec for _, spec in sorted(self._run_sensors.items())),
            program_name=name,
            program_sha256=digest,
            bundled=bundled,
        )

    def run_so_far(self) -> RunEntry | None:
        """The run under way as it stands (ended :data:`UNDER_WAY`), None when none is."""
        return self._entry(UNDER_WAY) if self._run_open else None

    def close(self) -> None:
        """End the session: an open run is kept (with its record) as stopped."""
        if self._run_open:
            self._close_run(STOPPED)
