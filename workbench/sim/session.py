"""One robot, its controller and its recorder: what every front end drives and reads.

Physics steps at ``dt``; the controller (an FSM, or nothing while keys or a VIPLE program
drive) runs at the control rate ``control_hz`` on simulated time, and the run record gets one
line per control tick. A controller that has things due at their own times (a VIPLE program
file's Timers and sensor reports) is woken at exactly those times as well: the physics step
they fall in is split there. Front ends call :meth:`Session.step` (or :meth:`Session.run`), hand
commands to :meth:`Session.command`, and read :meth:`Session.snapshot`.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from types import MappingProxyType
from typing import Any, Protocol, runtime_checkable

from .driver import NOBODY, Driver
from .maze import Maze
from .metrics import Metrics, TurnCounter, efficiency
from .noise import NoiseSettings
from .record import Recorder
from .sensors import SensorSpec
from .world import EXIT, Pose, World

_NONE: frozenset[str] = frozenset()
#: the due time of a controller with nothing due
_NEVER = math.inf


class Controller(Protocol):
    """What decides motor commands each control tick (the FSM engine is one)."""

    @property
    def state(self) -> str | None: ...

    @property
    def variables(self) -> dict[str, Any]: ...

    def start(self, t: float) -> list[Any]: ...

    def tick(self, t: float, readings: dict[str, float], events: frozenset[str]) -> list[Any]: ...


#: a controller may also say when it next has something to do between control ticks (a VIPLE
#: program's Timer or sensor report): ``next_due() -> float | None``; the session then wakes it
#: with :meth:`Controller.tick` at exactly that simulated time, between physics steps if need be
NEXT_DUE = "next_due"


@runtime_checkable
class Quiet(Protocol):
    """A controller that says until when its control ticks would find nothing to do (a VIPLE
    program between its Timers and sensor reports): the session leaves those ticks out."""

    #: its sensor reports come at their own pace, so ``quiet_until`` holds whatever readings
    #: a tick brings
    paced: bool
    #: before this simulated time a tick changes nothing and commands nothing
    quiet_until: float


#: times closer than this are the same moment, seconds
_SAME = 1e-9


@dataclass(frozen=True)
class Snapshot:
    """Everything a front end shows about the session at one moment."""

    time: float
    pose: Pose
    block: tuple[int, int]
    readings: dict[int, float | int]
    sensors: tuple[SensorSpec, ...]
    driver: Driver
    state: str | None
    variables: dict[str, Any]
    metrics: Metrics
    events: tuple[str, ...] = field(default=())


class Session:
    def __init__(
        self,
        maze: Maze,
        profile: str = "unity",
        sensors: Sequence[SensorSpec] | None = None,
        noise: NoiseSettings | str | None = None,
        seed: int = 0,
        dt: float = 1 / 60,
        control_hz: float = 20.0,
        recorder: Recorder | None = None,
    ) -> None:
        self.world = World(maze, profile, sensors, noise, seed, dt)
        self._world_step = self.world.step
        #: the world's step, which a new maze keeps
        self._dt = self.world.dt
        self.maze = maze
        self.profile = self.world.profile
        self.recorder = recorder
        self.every = max(1, round(1.0 / (dt * control_hz)))
        self.shortest_blocks = maze.shortest_path_length()
        self.controller: Controller | None = None
        self._next_due: Callable[[], float | None] | None = None
        #: the controller again where it is :class:`Quiet` and paced, else None
        self._quiet: Quiet | None = None
        self.binding = {}
        self.driver = NOBODY
        self._reset_run_state()

    def _reset_run_state(self) -> None:
        self._steps = 0
        self._scheduled: tuple[int, Any] | None = None
        self._events: list[str] = []
        self._commands: list[Any] = []
        self._started = False
        #: when the controller next has something due (inf: nothing; asked each time it ran)
        self._set_due(_NEVER)
        self._turns = TurnCounter()
        self._last_angle = self.world.angle
        self._last_time = 0.0
        self.readings: dict[int, float | int] = self.world.read_sensors()
        self.last_events: tuple[str, ...] = ()

    # -- who drives ---------------------------------------------------------------------
    @property
    def binding(self) -> Mapping[str, int]:
        """The controller's sensor names -> ports, read-only: change it by assigning a new
        mapping. Each control tick walks the (name, port) pairs taken when it was set (a
        tuple, without an items() view per tick), which a change in place would not reach."""
        return MappingProxyType(self._binding)

    @binding.setter
    def binding(self, binding: Mapping[str, int]) -> None:
        self._binding = dict(binding)
        self._ports = tuple(self._binding.items())

    def attach(self, controller: Controller, binding: dict[str, int], driver: Driver) -> None:
        """Let ``controller`` drive; ``binding`` maps its sensor names to ports."""
        self.controller = controller
        self._next_due = getattr(controller, NEXT_DUE, None)
        self._quiet = controller if isinstance(controller, Quiet) and controller.paced else None
        self.binding = binding  # (the setter keeps a copy)
        self.driver = driver
        self._started = False
        self._set_due(_NEVER)

    def detach(self, driver: Driver = NOBODY) -> None:
        self.controller = None
        self._next_due = None
        self._quiet = None
        self._set_due(_NEVER)
        self.binding = {}
        self.driver = driver

    def command(self, cmd: Any, driver: Driver | None = None) -> None:
        """A command from outside the controller (a key, a VIPLE message).

        It cancels a command still waiting from :meth:`command_after`.
        """
        self._scheduled = None
        self.world.apply(cmd)
        self._commands.append(cmd)
        if driver is not None:
            self.driver = driver

    def command_after(self, seconds: float, cmd: Any) -> None:
        """Apply ``cmd`` after exactly ``seconds`` of simulated time (to the step)."""
        self._scheduled = (self._steps + max(1, round(seconds / self.world.dt)), cmd)

    def load_maze(
        self,
        maze: Maze,
        profile: str | None = None,
        sensors: Sequence[SensorSpec] | None = None,
        noise: NoiseSettings | str | None = None,
        seed: int | None = None,
    ) -> None:
        """Put the robot on ``maze``: a new world, the robot at the start, the run counted
        afresh and no controller attached.

        What is not given stays as it was: the profile, the sensors, the seed, and the noise
        (with a new profile and no noise given, that profile's own). The session stays the
        same object, so whatever serves it (VIPLE endpoints, a pacer) carries on with the new
        maze.
        """
        old = self.world
        same_profile = profile is None or profile == old.profile.name
        if noise is None and same_profile:
            noise = old.noise
        self.world = World(
            maze,
            old.profile if profile is None else profile,
            list(old.sensors if sensors is None else sensors),
            noise,
            old.seed if seed is None else seed,
            old.dt,
        )
        self._world_step = self.world.step
        self.profile = self.world.profile
        self.maze = maze
        self.shortest_blocks = maze.shortest_path_length()
        self.controller = None
        self._next_due = None
        self._quiet = None
        self.binding = {}
        self._reset_run_state()

    def set_sensors(self, specs: Sequence[SensorSpec]) -> None:
        self.world.set_sensors(list(specs))
        self.readings = self.world.read_sensors()

    def reset(self, seed: int | None = None) -> None:
        """Robot back to the start, odometry and controller state cleared."""
        self.world.reset(seed)
        reset = getattr(self.controller, "reset", None)
        if reset is not None:
            reset()
        self._reset_run_state()

    # -- time ----------------------------------------------------------------------------
    def step(self) -> tuple[str, ...]:
        """One physics step (and a control tick every ``every`` steps); a controller with
        something due inside the step is woken at that time."""
        n = self._steps + 1
        # something due inside this step? (only asked from a step near the due time: never, as
        # for a controller without next_due, when nothing is due)
        if n >= self._due_near and self._due < n * self._dt - _SAME:
            early = self._wake_within()
            events = self._world_step()
            if early:
                events = early + events
        else:
            events = self._world_step()
        if events:
            self._events.extend(events)
        self._steps = n
        if self._scheduled is not None and n >= self._scheduled[0]:
            cmd = self._scheduled[1]
            self._scheduled = None
            self.world.apply(cmd)
            self._commands.append(cmd)
        if n % self.every == 0:
            self._control_tick()
        elif n >= self._due_near and self._due <= self.world.time + _SAME:
            self._wake(self.world.time)
        return events

    def _wake_within(self) -> tuple[str, ...]:
        """Wake the controller at each time it has something due before this step ends,
        moving the world to that time first; the events on the way."""
        world = self.world
        end = (self._steps + 1) * world.dt - _SAME
        events: tuple[str, ...] = ()
        last = -math.inf
        due = self._due
        while last < due < end:
            if due > world.time + _SAME:
                events += world.step_to(due)
            self._wake(max(due, world.time))
            last = due
            due = self._due
        return events

    def _ask_due(self) -> None:
        """After the controller ran: when it next has something due (inf: nothing)."""
        next_due = self._next_due
        if next_due is not None:
            due = next_due()
            self._set_due(_NEVER if due is None else due)

    def _set_due(self, due: float) -> None:
        """The controller next has something due at ``due``: :meth:`step` tests whether it
        falls inside a step (``due < n * dt - _SAME``) or at its end (``due <= time + _SAME``)
        from the step two before the one it falls in on, and leaves the tests out before."""
        self._due = due
        if abs(due) < self._dt * 1e14:
            # of any earlier step n, n * dt is more than a step short of due, so both tests
            # are false (the rounding of these products is far under a step)
            self._due_near: float = int(due / self._dt) - 2
        elif due == _NEVER or due != due:
            self._due_near = _NEVER  # nothing due, or nan: neither test ever holds
        else:
            self._due_near = 0  # beyond any run: both tests at every step, as ever

    def _wake(self, t: float) -> None:
        """The controller's due work at ``t`` between control ticks: it gets the readings of
        that moment and its commands apply at once (the record shows them at the next tick)."""
        controller = self.controller
        assert controller is not None
        world = self.world
        self.readings = readings = world.read_sensors()
        # by the controller's names (a plain loop: a comprehension costs a frame of its own)
        named = {}
        for name, port in self._ports:
            named[name] = readings[port]
        commands = controller.tick(t, named, _NONE)
        self._ask_due()
        if commands:
            for cmd in commands:
                world.apply(cmd)
            self._commands.extend(commands)

    def _control_tick(self, run_controller: bool = True) -> None:
        world = self.world
        t = world.time
        self.readings = readings = world.read_sensors()
        angle = world.angle
        last = self._last_angle
        turns = self._turns
        # not turned since the last tick and no sweep to end: the update would change nothing
        if angle != last or turns.sweep:
            turns.update(math.degrees(angle - last), t - self._last_time)
        self._last_angle = angle
        self._last_time = t
        events = self._events
        controller = self.controller
        quiet = self._quiet
        if quiet is not None and t + _SAME < quiet.quiet_until and self._started:
            pass  # its tick would find nothing to do (no Timer ends, no report or key comes)
        elif controller is not None and run_controller:
            if self._started:
                named = {}  # as in _wake
                for name, port in self._ports:
                    named[name] = readings[port]
                commands = controller.tick(t, named, frozenset(events) if events else _NONE)
            else:
                self._started = True
                commands = controller.start(t)
            if self._next_due is not None:  # (an FSM has none: no call to ask nothing)
                self._ask_due()
            if commands:
                for cmd in commands:
                    world.apply(cmd)
                self._commands.extend(commands)
        if self.recorder is not None:
            self.recorder.tick(
                t,
                world.pose,
                readings,
                self._commands,
                controller.state if controller is not None else None,
                events,
                controller.variables if controller is not None else None,
            )
        if events or self.last_events:
            self.last_events = tuple(events)
            self._events = []
        if self._commands:
            self._commands = []

    @property
    def still(self) -> bool:
        """True while nothing on the robot changes but the clock: it stands with its motors off,
        no controller drives it and no command waits to be applied."""
        return self.controller is None and self._scheduled is None and self.world.still

    @property
    def settled(self) -> bool:
        """As :attr:`still`, with the robot standing to the eye (:attr:`World.settled`): what
        is left to change can not be seen."""
        return self.controller is None and self._scheduled is None and self.world.settled

    @property
    def reached_exit(self) -> bool:
        return self.world.odometry.exit_time is not None

    def run(
        self,
        max_time: float,
        stop_at_exit: bool = True,
        given_up: Callable[[], bool] | None = None,
    ) -> Metrics:
        """Step until an exit is reached (when the maze has exits), ``max_time`` passes, or
        ``given_up()`` says the controller will never move the robot again."""
        steps = math.ceil(max_time / self.world.dt - 1e-9)
        step = self.step
        stop = stop_at_exit and bool(self.maze.exits)
        for _ in range(steps - self._steps):
            if EXIT in step() and stop:
                break
            if given_up is not None and given_up():
                break
        self.settle()
        return self.metrics()

    def settle(self) -> None:
        """At the end of a run: the steps since the last control tick reach the readings, the
        turn count and the record (a tick without the controller)."""
        if self._steps % self.every:
            self._control_tick(run_controller=False)

    # -- reading -------------------------------------------------------------------------
    def metrics(self) -> Metrics:
        odo = self.world.odometry
        reached = odo.exit_time is not None
        cell = self.world.cell
        return Metrics(
            reached_exit=reached,
            exit_time=odo.exit_time,
            sim_time=odo.time,
            distance=odo.distance,
            distance_cells=odo.distance / cell,
            turn_degrees=odo.turn_degrees,
            turns=self._turns.current(),
            collisions=odo.collisions,
            efficiency=efficiency(self.shortest_blocks, cell, odo.distance, reached),
            touches=odo.touches,
        )

    def snapshot(self) -> Snapshot:
        controller = self.controller
        return Snapshot(
            time=self.world.time,
            pose=self.world.pose,
            block=self.world.block,
            readings=dict(self.readings),
            sensors=self.world.sensors,
            driver=self.driver,
            state=controller.state if controller is not None else None,
            variables=dict(controller.variables) if controller is not None else {},
            metrics=self.metrics(),
            events=self.last_events,
        )

    def record_header(self, **fields: Any) -> None:
        """Write the run record's header: the maze, the set-up, and ``fields`` (algorithm...)."""
        if self.recorder is None:
            return
        world = self.world
        self.recorder.header(
            maze={
                "name": self.maze.name,
                "source": self.maze.source,
                "digest": self.maze.digest(),
                "shortest_path": self.shortest_blocks,
            },
            profile=self.profile.name,
            cell=world.cell,
            sensors=[str(s) for s in world.sensors],
            seed=world.seed,
            noise=world.noise.as_dict(),
            dt=world.dt,
            control_hz=1.0 / (world.dt * self.every),
            **fields,
        )

    def record_summary(self, **extra: Any) -> None:
        if self.recorder is not None:
            self.recorder.summary(self.metrics().as_dict(), **extra)
