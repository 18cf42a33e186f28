"""Running a compiled VIPLE program as the controller of a simulation session.

The model is VIPLE's dataflow: a message arrives at an activity, the activity runs once and
sends one message to every target of the output pin it chose. Each event (a key, a sensor
report, a start message) and each extra branch of a fan-out is a *flow* of its own. Flows are
scheduled on the simulation clock, deterministically: at each tick the timers that are due
wake first (earliest first), then key events, then a sensor report if one is due (activities
in file order), then the ready flows run in turn, each for a slice of :data:`SLICE`
activities. A flow that ran :data:`FLOW_TICK_STEPS` activities in one tick, or that loops in a
While without anything having changed since its last pass, waits for the next tick, so a
busy-waiting loop never freezes the others. A Timer puts only its own flow to sleep, until its
own time: :meth:`ProgramController.next_due` says when the next Timer, scripted key or sensor
report is due, and the session (or the remote runner) ticks the program at exactly that time.

Sensor reports come at the pace VIPLE's simulator sends them (``report_period``, the profile's
250 ms offline), or, with no period, with every set of readings the caller gives (a real
robot's own reports).

A program's work and memory are bounded (:class:`Limits`): the activities run in one control
tick and in one simulated second, and the parts of the values it holds (messages on their way,
messages waiting at Joins, variables). A program past a limit is stopped: :attr:`stopped` says
when, at which activity and why, the robot is told to stop, and nothing of it runs again.
"""

from __future__ import annotations

import functools
import itertools
import json
import math
from collections import deque
from collections.abc import Callable
from dataclasses import dataclass, field
from heapq import heappop, heappush
from typing import Any

from workbench.sim.commands import MotorPower, MoveAtPower, Stop, TurnByDegrees, WheelPowers

from . import kinds as K
from .code import first_sensor_value
from .compiled import DEFAULTS, Compiled
from .fused import COUNT, ENDED, PARKS, SLEEPS, Chain, Fusable, fuse
from .keys import KeyEvent, TypedKeys
from .model import ELSE
from .readings import pressed, sensor_message, touch_problem
from .viple_expr import (
    INT_LIMIT,
    ExprError,
    JoinMessage,
    LimitError,
    Scope,
    Value,
    join_message,
    parts_of,
    show,
    type_name,
    want_bool,
)

SLICE = 50
FLOW_TICK_STEPS = 5_000
MAX_FLOWS = 2_000
MAX_CALL_DEPTH = 64
MAX_PRINTED = 5_000
MAX_ERRORS = 100
MAX_FIRED = 5_000
#: the shortest wait a Timer takes, seconds (VIPLE counts whole milliseconds); a Timer of 0 ms
#: or less only lets the other ready flows go first. Timers end on the clock's whole
#: milliseconds, so however many flows wait, the program wakes at most 1,000 times a second.
MIN_WAIT = 0.001
#: times closer than this are the same moment, seconds
_SAME = 1e-9
_NEVER = float("inf")
#: the newest printed lines a live console keeps (the list of all stops at MAX_PRINTED)
RECENT_PRINTED = 200
#: messages waiting at one input of a Join
MAX_JOIN_QUEUE = 1_000


@dataclass(frozen=True)
class Limits:
    """What one program may use; past any of them it is stopped with a message."""

    #: activities run in one control tick, all flows together (the rest wait for the next);
    #: real programs run at most about 50 in a tick
    tick: int = 2_500
    #: activities run in the last simulated second, all flows together (real programs run a
    #: few hundred): a program may compute in bursts, but not without pause
    second: int = 50_000
    #: parts of the values the program holds at once, written out (a text counts one part
    #: for each 100 characters): messages on their way, waiting at Joins, in variables
    memory: int = 1_000_000


#: activities that run at the start when nothing links into them
_STARTS = frozenset((K.DATA, K.CALCULATE, K.BLOCK))
#: activities that pass the message straight on when one arrives
_PASS_ON = frozenset(
    (
        K.MERGE,
        K.INPUT_PIN,
        K.KEY_PRESS,
        K.KEY_RELEASE,
        K.TOUCH,
        K.DISTANCE,
        K.OTHER_SENSOR,
        K.RAW_SENSOR,
    )
)


@dataclass(frozen=True)
class Printed:
    time: float
    text: str


@dataclass(frozen=True)
class Fired:
    """An event the program answered: a key, a release, a custom event, a touch."""

    time: float
    activity: int
    what: str


@dataclass(frozen=True)
class RunError:
    time: float
    panel: str
    activity: int
    label: str
    message: str

    def __str__(self) -> str:
        return (
            f"{self.time:.2f} s: panel {self.panel}: activity {self.activity} ({self.label}): "
            f"{self.message}"
        )


@dataclass(slots=True)
class Frame:
    """One running custom activity (``block`` None: Main, or an event inside a panel)."""

    panel: str
    instance: dict[str, Value]
    block: int | None = None
    parent: Frame | None = None
    depth: int = 0
    #: this call's Joins: Join id -> one queue per input (gone with the call)
    joins: dict[int, list[deque[Value]]] = field(default_factory=dict)


@dataclass(slots=True)
class Flow:
    number: int
    activity: int
    value: Value
    frame: Frame
    in_pin: int = 0
    steps: int = 0
    #: While id -> (changes, message) at its last pass, to notice a loop that changes nothing
    #: (None until the flow meets a While: most flows never do, and a flow starts with every
    #: sensor report)
    loops: dict[int, tuple[int, Any]] | None = None
    #: the activities a chain ran when one of them raised (see fused.py)
    ran: int = 0
    #: the seconds a Timer's chain puts the flow to sleep for
    wait: float = 0.0


def _state(busy: int) -> str:
    """What a program's state says: how many flows it has."""
    return f"{busy} flow{'s' if busy != 1 else ''}"


#: the states of the fewest flows, made once (the state changes whenever a flow starts or ends)
_STATES = tuple(_state(n) for n in range(100))

#: the frame of a flow that ended (see ProgramController._spawn)
_NO_FRAME = Frame("", {})

#: one activity made ready to run: a flow at it -> does the flow go on?
Step = Callable[[Flow], bool]
#: sends a message out of one output pin of an activity: the flow, the message -> goes on?
Send = Callable[[Flow, Value], bool]


class _Sleep(Exception):
    def __init__(self, seconds: float) -> None:
        self.seconds = seconds


class _Park(Exception):
    pass


class ProgramController:
    """A :class:`workbench.sim.session.Controller` that runs a VIPLE program."""

    # every attribute a slot: a tick reads and sets a hundred of them, and a slot is found
    # without a dictionary's lookup (there are too many for the instance dictionaries CPython
    # shares between objects of a class)
    __slots__ = (
        "_activities", "_busy", "_chains", "_count_flows", "_due", "_due_or_none", "_exprs",
        "_fires", "_handlers", "_held", "_hot", "_join_parts", "_joins", "_key_due",
        "_keys_pending", "_keys_typed", "_main", "_next_key", "_next_report", "_numbers",
        "_outputs", "_parked", "_parsed", "_period", "_plan", "_ports", "_pushed", "_reads",
        "_ready", "_report", "_runs", "_second_steps", "_senses", "_sleeping", "_spare", "_steps",
        "_the_scope", "_touch", "_typed", "_var_keys", "_window", "changes", "commands", "compiled",
        "errors", "errors_total", "fired", "flows_dropped", "globals", "key_script", "limits",
        "next_due", "now", "paced", "printed", "printed_dropped", "printed_total", "program",
        "quiet_until", "recent", "report_period", "state", "steps", "stopped",
    )  # fmt: skip

    def __init__(
        self,
        compiled: Compiled,
        keys: tuple[KeyEvent, ...] = (),
        report_period: float | None = None,
        limits: Limits = Limits(),
        fuse: bool = True,
    ) -> None:
        """``fuse``: run the program's chains of activities fused (fused.py), else every
        activity by its own step (the same run, slower: the tests compare the two)."""
        self.compiled = compiled
        self.program = compiled.program
        self.key_script = keys
        self.limits = limits
        #: seconds between two sensor reports (None: every tick that brings readings reports)
        if report_period is not None and not report_period > 0:
            raise ValueError(f"the report period must be above 0 s, not {report_period!r}")
        self.report_period = report_period
        #: whether sensor reports come at their own pace (else with every tick's readings)
        self.paced: bool = report_period is not None
        self._period = report_period if report_period is not None else 0.0
        self._reads = bool(compiled.sensors)
        #: each activity's output pins and their links (Program.targets, without the call)
        self._outputs = compiled.program.outputs
        #: a Variable activity's id -> the global it sets (lower case)
        self._var_keys = {
            aid: act.value(0).strip().lower()
            for aid, act in compiled.program.activities.items()
            if act.kind == K.VARIABLE
        }
        #: activity kind -> its handler, with the kinds this program's mapping file names
        self._runs = {
            **{kind: MAPPED_RUNS[m.activity] for kind, m in compiled.program.kinds.items()},
            **RUNS,
        }
        self._activities = compiled.program.activities
        #: activity id -> (its handler, the activity), looked up once instead of every step
        self._handlers = {
            aid: (self._runs.get(act.kind, _NEVER_RUNS), act)
            for aid, act in compiled.program.activities.items()
        }
        #: activity id -> its compiled expressions in value order (If and Switch walk them)
        exprs: dict[int, list[Any]] = {}
        for (aid, index), expression in sorted(compiled.expressions.items()):
            exprs.setdefault(aid, []).append((index, expression))
        #: the same, parsed (what a fused chain writes out as code)
        self._parsed = {
            aid: tuple(e for _, e in pairs)
            for aid, pairs in exprs.items()
            if [i for i, _ in pairs] == list(range(len(pairs)))
        }
        self._exprs = {aid: tuple(e.run for e in parsed) for aid, parsed in self._parsed.items()}
        #: a sensor or event activity's id -> its panel and the links out of it
        self._fires = {
            aid: (act.panel, compiled.program.targets(aid))
            for aid, act in compiled.program.activities.items()
        }
        #: the sensor activities in file order: what each does with a report, its id and port
        self._senses = tuple(
            (SENSES[kind], aid, port) for aid, (kind, port) in compiled.sensors.items()
        )
        #: the scope expressions read, filled in for each activity that runs them (nothing
        #: keeps it: an expression runs to its end before the next activity starts)
        self._the_scope = Scope()
        #: activity id -> the step that runs it (see _prepare)
        self._steps = {aid: self._prepare(act) for aid, act in self._activities.items()}
        #: activity id -> the chain a flow at it runs (see fused.py): fused from the activity
        #: on where it heads a chain, else its step alone
        self._chains = {aid: _single(aid, step) for aid, step in self._steps.items()}
        if fuse:
            self._chains.update(self._fuse())
        #: whether a flow may run FLOW_TICK_STEPS activities in one tick (a tick's budget
        #: under that never lets one: every flow has run fewer than the tick's total)
        self._count_flows = limits.tick > FLOW_TICK_STEPS
        self.next_due = functools.partial(getattr, self, "_due_or_none")
        self.reset()

    # -- the Controller protocol ----------------------------------------------------------
    def reset(self) -> None:
        self.globals: dict[str, Value] = {
            key: DEFAULTS.get(vtype) for key, (_, vtype) in self.compiled.globals.items()
        }
        self.printed: list[Printed] = []
        self.printed_dropped = 0
        #: every line printed so far, counted, and the newest of them
        self.printed_total = 0
        self.recent: deque[Printed] = deque(maxlen=RECENT_PRINTED)
        self.fired: list[Fired] = []
        self.errors: list[RunError] = []
        #: every run-time error, counted (``errors`` keeps the first MAX_ERRORS)
        self.errors_total = 0
        self.commands: list[Any] = []
        self.changes = 0
        self.now = 0.0
        self._numbers = itertools.count()
        self._ready: deque[Flow] = deque()
        #: flows that ended, to be made new flows (see _spawn)
        self._spare: list[Flow] = []
        self._parked: list[Flow] = []
        self._sleeping: list[tuple[float, int, Flow]] = []
        #: the Joins of Main and of events inside panels (a block call keeps its own)
        self._joins: dict[int, list[deque[Value]]] = {}
        #: the frame of every flow of Main that no block call made (all of them alike: Main
        #: has no parameters and keeps its Joins in _joins)
        self._main = Frame("Main", {})
        self._held: set[str] = set()
        self._next_key = 0
        self._typed = TypedKeys()
        self._pushed: list[KeyEvent] = []
        self._note_keys()
        self._touch: dict[int, int] = {}
        #: the report being handed to the sensor activities (a raw sensor's message)
        self._report: str | None = None
        #: a reading's name ("port 3") -> its port
        self._ports: dict[str, int] = {}
        #: the names of the last report's readings and what the sensor activities do with
        #: them (see _plan_for)
        self._plan: tuple[set[str], list[Callable]] | None = None
        self._next_report = _NEVER
        #: the earliest of the times above and the sleeping flows' (what next_due says; kept
        #: up to date at the end of every tick that did something, the only place they change)
        self._due = _NEVER
        #: before this time, a tick finds nothing to do (see _refresh_due): any tick of a
        #: :attr:`paced` program, else one that brings no readings and no report (the session
        #: leaves such ticks out)
        self.quiet_until = -_NEVER
        self.flows_dropped = 0
        self.steps = 0
        self.state: str | None = None
        #: how many flows ``state`` counts
        self._busy = -1
        #: why and where the program was stopped (None while it may run)
        self.stopped: RunError | None = None
        #: the activities run at each run of the last simulated second, and their sum
        self._window: deque[tuple[float, int]] = deque()
        self._second_steps = 0
        #: where flows were at the end of each slice, and how many activities they had run
        #: there (the busiest is named if the budget runs out)
        self._hot: dict[int, int] = {}
        #: parts of the messages waiting at Joins
        self._join_parts = 0
        self._refresh_due()

    @property
    def variables(self) -> dict[str, Any]:
        names = self.compiled.globals
        return {names[k][0]: v for k, v in self.globals.items() if v is None or _plain(v)}

    def start(self, t: float) -> list[Any]:
        self.now = t
        if self.report_period is not None and self._reads:
            self._next_report = t + self.report_period
        program = self.program
        main = self._main
        for aid in program.panels["Main"].activities:
            act = program.activities[aid]
            if act.kind in _STARTS and aid not in program.inputs:
                self._spawn(aid, None, main)
        return self._run()

    def tick(
        self,
        t: float,
        readings: dict[str, Value],
        events: frozenset[str],
        report: str | None = None,
    ) -> list[Any]:
        """One control tick; ``readings`` ("port N" -> value) fire the sensor activities, and
        ``report``, a robot's report as it arrived, is what a raw sensor gets (None: the
        simulated robot's report is made from the readings)."""
        if t + _SAME < self.quiet_until and (self.paced or (not readings and report is None)):
            # nothing is due: no Timer ends, no key or sensor report comes and no flow waits to
            # run, so this tick would change nothing (most ticks of a program: its sensors
            # report every 250 ms, the session ticks it every 50 ms); ``now`` is only read
            # while the program runs, so it is set below
            return []
        self.now = t
        if self.stopped is not None:
            return []
        soon = t + _SAME
        sleeping = self._sleeping
        while sleeping and sleeping[0][0] <= soon:
            self._ready.append(heappop(sleeping)[2])
        if self._parked:
            self._ready.extend(self._parked)
            self._parked = []
        if self._keys_pending:
            self._keys(t)
        if (soon >= self._next_report if self.paced else self._report_due(t)) and (
            readings or report is not None
        ):
            # a tick between two reports (of a remote robot, or of the paced simulator) fires
            # no sensor; the next paced report is on the same grid after t (a late tick skips
            # the missed ones; as _report_due)
            if self.paced:
                start = self._next_report
                period = self._period
                late = soon - start
                # a report on time (late by less than a period, so the floor is 0): the same
                # sum, without the division
                self._next_report = (
                    start + period if late < period else start + period * (1 + int(late // period))
                )
            plan = self._plan
            if report is not None or plan is None or readings.keys() != plan[0]:
                plan = self._plan = self._plan_for(readings) if report is None else None
            if plan is not None:
                for sense in plan[1]:
                    sense(readings)
            else:
                ports = self._ports
                by_port = {ports.get(n) or _port(ports, n): v for n, v in readings.items()}
                self._sensors(by_port, report)
        return self._run()

    #: ``next_due()``: when the program next has something to do at a time of its own: a
    #: Timer ends, a scripted key is pressed or a sensor report is due (None: nothing is).
    #: The session asks after every tick, so it is a getter of ``_due_or_none`` made in C
    #: (set in __init__), not a method.
    next_due: Callable[[], float | None]

    def _refresh_due(self) -> None:
        """Work out :meth:`next_due` again, after the flows, keys or reports changed, and until
        when the program is quiet: nothing due, no flow ready or waiting for the next tick, no
        key typed or held (a stopped program is never quiet; its ticks return at once too)."""
        due = self._next_report
        sleeping = self._sleeping
        if sleeping and sleeping[0][0] < due:
            due = sleeping[0][0]
        if self._key_due < due:
            due = self._key_due
        self._due = due
        self._due_or_none = None if due == _NEVER else due
        quiet = not (self._ready or self._parked or self._keys_typed)
        self.quiet_until = due if quiet and self.state is not None else -_NEVER

    @property
    def timing(self) -> bool:
        """Whether something of the program runs on its own clock now: a Timer sleeps, or a
        scripted key is still to come (the time between its commands is then the program's
        to say)."""
        return bool(self._sleeping) or self._next_key < len(self.key_script)

    def _report_due(self, t: float) -> bool:
        period = self.report_period
        if period is None:
            return True
        if t + _SAME < self._next_report:
            return False
        # the next report on the same grid after t (a late tick skips the missed ones)
        start = self._next_report
        self._next_report = start + period * (1 + int((t + _SAME - start) // period))
        return True

    # -- events --------------------------------------------------------------------------
    def type_key(self, key: str, t: float) -> None:
        """A key typed on a terminal at ``t`` (it fires at the next tick); the release comes by
        :class:`TypedKeys`'s rule."""
        if self.stopped is not None:
            return
        self._pushed += self._typed.press(key.lower(), t)
        self._note_keys()
        self.quiet_until = -_NEVER  # the key fires at the next tick

    def _note_keys(self) -> None:
        """After the keys changed (the script's next key, keys typed or held): when the next
        scripted key is due, and whether a tick has keys to see to (what ``tick`` and
        ``_refresh_due`` read, instead of asking the script and the typed keys each time)."""
        script = self.key_script
        left = self._next_key < len(script)
        self._key_due = script[self._next_key].time if left else _NEVER
        #: keys typed and not yet fired, or one held until its release is due
        self._keys_typed = bool(self._pushed or self._typed.held)
        self._keys_pending = left or self._keys_typed

    @property
    def held(self) -> frozenset[str]:
        """The keys the program sees held now."""
        return frozenset(self._held)

    def _keys(self, t: float) -> None:
        script = self.key_script
        if self._next_key >= len(script) and not self._pushed and not self._typed.held:
            return  # no key is due, typed or waiting for its release
        while self._next_key < len(script) and script[self._next_key].time <= t + 1e-9:
            self._next_key += 1
            self._key_event(script[self._next_key - 1])
        release = self._typed.due(t)
        if release is not None:
            self._pushed.append(release)
        pushed, self._pushed = self._pushed, []
        for event in pushed:
            self._key_event(event)
        self._note_keys()

    def _key_event(self, event: KeyEvent) -> None:
        """One press or release, from a key script or typed: the one way keys reach events."""
        if event.release:
            self._held.clear()
            for act in self._sources(K.KEY_RELEASE):
                self._fire(act.id, "", "key release")
            return
        self._held |= event.keys
        for act in self._sources(K.KEY_PRESS):
            wanted = self.compiled.key_sets.get(act.id, frozenset())
            if wanted and wanted <= self._held and wanted & event.keys:
                self._fire(act.id, "+".join(sorted(wanted)), f"key {'+'.join(sorted(wanted))}")

    def _sensors(self, readings: dict[int, Value], report: str | None) -> None:
        """One sensor report: each sensor activity, in file order, through the handler of its
        kind (:data:`SENSES`)."""
        self._report = report
        for sense, aid, port in self._senses:
            sense(self, aid, port, readings)

    def _plan_for(self, named: dict[str, Value]) -> tuple[set[str], list[Callable]] | None:
        """How a report of readings with these names reaches the sensor activities without
        making the readings by port first (what ``_sensors`` is given): for each sensor
        activity in file order, what it does with the reading of the one name of its port.
        None where that is not the same: a raw sensor (it reads every port), a name that is
        not ``port N``, two names of one port."""
        ports: dict[int, str] = {}
        for name in named:
            try:
                port = int(name.split()[-1])
            except (ValueError, IndexError):
                return None
            if port in ports:
                return None
            ports[port] = name
        plan = []
        for sense, aid, port in self._senses:
            if sense is ProgramController._sense_raw:
                return None
            reading = ports.get(port)
            if reading is None:
                continue  # the report has no reading of its port: the activity does nothing
            if sense is ProgramController._sense_touch:
                plan.append(self._touch_plan(aid, port, reading))
            else:
                plan.append(self._value_plan(aid, reading))
        return set(named), plan

    def _value_plan(self, aid: int, name: str) -> Callable[[dict[str, Value]], None]:
        """``_sense_value`` for the reading ``name``, its flows started as ``_fire`` starts
        them."""
        panel, links = self._fires[aid]
        if panel != "Main" or len(links) != 1:

            def fire_all(named: dict[str, Value]) -> None:
                self._fire(aid, sensor_message(named[name]))

            return fire_all
        target, in_pin = links[0].target, links[0].in_pin
        spawn = self._spawn

        def fire_one(named: dict[str, Value]) -> None:
            value = named[name]
            if isinstance(value, str):
                value = sensor_message(value)
            spawn(target, value, self._main, in_pin)

        return fire_one

    def _touch_plan(self, aid: int, port: int, name: str) -> Callable[[dict[str, Value]], None]:
        """``_sense_touch`` for the reading ``name``."""
        by_port = {}

        def touch(named: dict[str, Value]) -> None:
            value = named[name]
            kind = type(value)
            if kind is int or kind is float:
                # as _sense_touch: the state kept is 1 while pressed (an activity never
                # pressed has none, which reads as 0)
                if value != 0:
                    if not self._touch.get(aid, 0):
                        self._touch[aid] = 1
                        self._fire(aid, 1, f"touch {port}")
                elif self._touch.get(aid, 0):
                    self._touch[aid] = 0
            else:
                by_port[port] = value
                self._sense_touch(aid, port, by_port)

        return touch

    def _sense_raw(self, aid: int, port: int, readings: dict[int, Value]) -> None:
        if self._report is None:  # the simulated robot: a report made from its readings
            self._report = json.dumps(
                {
                    "sensors": [
                        {"name": f"sensor{p}", "id": p, "value": readings[p]}
                        for p in sorted(readings)
                    ]
                }
            )
        self._fire(aid, self._report)

    def _sense_value(self, aid: int, port: int, readings: dict[int, Value]) -> None:
        if port in readings:
            self._fire(aid, sensor_message(readings[port]))

    def _sense_touch(self, aid: int, port: int, readings: dict[int, Value]) -> None:
        """A touch sensor fires when it is pressed, not while it stays pressed."""
        if port not in readings:
            return
        value = sensor_message(readings[port])
        down = pressed(value)
        if down is None:
            self._error(aid, touch_problem(port, value))
            return
        before = self._touch.get(aid, 0)
        self._touch[aid] = int(down)
        if down and not before:
            self._fire(aid, 1, f"touch {port}")

    def _sources(self, kind: int):
        return [a for a in self.program.activities.values() if a.kind == kind]

    def _fired(self, aid: int, what: str) -> None:
        if len(self.fired) < MAX_FIRED:
            self.fired.append(Fired(self.now, aid, what))

    def _fire(self, aid: int, value: Value, what: str | None = None) -> None:
        panel, links = self._fires[aid]
        if what is not None:
            self._fired(aid, what)
        frame = self._main if panel == "Main" else Frame(panel, self._instance_defaults(panel))
        for link in links:
            self._spawn(link.target, value, frame, link.in_pin)

    def _instance_defaults(self, panel: str) -> dict[str, Value]:
        if panel == "Main":
            return {}
        return {v.name.lower(): DEFAULTS.get(v.type) for v in self.program.panels[panel].inputs}

    # -- what runs now (for a live panel) -----------------------------------------------------
    def running(self, limit: int = 20) -> list[tuple[str, str, str]]:
        """The live flows' current activities, oldest flow first: (panel, activity, what it
        does: ``ready``, ``waiting`` for the next tick, or ``sleeping``)."""
        flows = [(f, "ready") for f in self._ready] + [(f, "waiting") for f in self._parked]
        flows += [(f, "sleeping") for _, _, f in self._sleeping]
        flows.sort(key=lambda item: item[0].number)
        out = []
        for flow, what in flows[:limit]:
            act = self.program.activities[flow.activity]
            out.append((act.panel, self.program.label(act), what))
        return out

    # -- scheduling ----------------------------------------------------------------------
    def _spawn(self, aid: int, value: Value, frame: Frame, in_pin: int = 0) -> None:
        live = len(self._ready) + len(self._parked) + len(self._sleeping)
        if live >= MAX_FLOWS:
            self.flows_dropped += 1
            if self.flows_dropped == 1:
                self._error(aid, f"more than {MAX_FLOWS:,} flows at once: new messages dropped")
            return
        self.changes += 1
        spare = self._spare
        if spare:  # a flow that ended, made a new one (nothing holds an ended flow)
            flow = spare.pop()
            flow.number, flow.activity, flow.value = next(self._numbers), aid, value
            flow.frame, flow.in_pin, flow.steps = frame, in_pin, 0
            self._ready.append(flow)
        else:
            self._ready.append(Flow(next(self._numbers), aid, value, frame, in_pin))

    def _run(self) -> list[Any]:
        """Run the ready flows (their slices in turn, within the tick's budget); then work
        out what is due next (``_refresh_due``)."""
        ready = self._ready
        if not ready and self.state is not None:
            self._refresh_due()
            return []  # nothing ran, so nothing changed since the last pass
        now = self.now
        limits = self.limits
        window = self._window
        while window and window[0][0] <= now - 1.0 + 1e-9:
            self._second_steps -= window.popleft()[1]
        if not window and self._hot:
            self._hot = {}
        total = 0
        budget = limits.second - self._second_steps
        if limits.tick < budget:
            budget = limits.tick
        hot = self._hot
        chains = self._chains
        parked = self._parked
        spare = self._spare
        #: the flows that took steps in this pass, when their count matters (it restarts)
        ran: list[Flow] | None = [] if self._count_flows else None
        while ready and total < budget and self.stopped is None:
            flow = ready.popleft()
            if ran is not None and flow.steps >= FLOW_TICK_STEPS:
                parked.append(flow)
                continue
            # one slice: the chains from the flow's activity on, SLICE activities at most;
            # a run-time error ends the flow, a limit stops the program
            done = 0
            while True:
                try:
                    result = chains[flow.activity](flow, SLICE - done)
                except LimitError as exc:
                    result = flow.ran | ENDED
                    self._stop(flow.activity, str(exc))
                except (ExprError, ValueError, TypeError, OverflowError) as exc:
                    result = flow.ran | ENDED
                    self._error(flow.activity, str(exc))
                done += result & COUNT
                if result < ENDED and done < SLICE:
                    continue
                break
            total += done
            if result & ENDED:
                # it keeps nothing alive
                flow.frame, flow.value, flow.loops = _NO_FRAME, None, None
                spare.append(flow)
                continue
            if result & SLEEPS:
                wait = flow.wait
                if wait > 0:
                    # at least MIN_WAIT, up to the clock's next whole millisecond (the time
                    # itself when it is one, or when it lies beyond any run: an endless wait
                    # stays endless)
                    due = now + (wait if wait > MIN_WAIT else MIN_WAIT)
                    if due < 1e12:
                        due = math.ceil(due * 1000.0 - 1e-6) / 1000.0
                    heappush(self._sleeping, (due, flow.number, flow))
                else:
                    ready.append(flow)
            elif result & PARKS:
                parked.append(flow)
            else:
                ready.append(flow)  # its slice is over: the other flows go first
            if ran is not None:
                flow.steps += done
                ran.append(flow)
            hot[flow.activity] = hot.get(flow.activity, 0) + done
        self.steps += total
        if total:
            self._second_steps += total
            window.append((now, total))
        stopped = self.stopped
        if stopped is None and (ready or parked or self._join_parts):
            if (ready or parked) and self._second_steps >= limits.second:
                self._over_work()
            else:
                self._check_memory()
            stopped = self.stopped
        if stopped is not None:
            commands = self._halted()
            self._refresh_due()
            return commands
        if ran is not None:
            for flow in ran:
                flow.steps = 0
        sleeping = self._sleeping
        busy = len(ready) + len(parked) + len(sleeping)
        if busy != self._busy:  # (-1 until the first pass sets the state)
            self._busy = busy
            self.state = _STATES[busy] if busy < len(_STATES) else _state(busy)
        commands, self.commands = self.commands, []
        self._refresh_due()
        return commands

    # -- one activity ----------------------------------------------------------------------
    def _prepare(self, act) -> Step:
        """The step that runs ``act``: for the kinds most programs run at every report
        (:data:`PREPARED`), made here with the activity's links, constant and compiled
        expressions looked up once instead of at every step; else the handler of its kind
        (:data:`RUNS`; a kind named in a mapping file, through :data:`MAPPED_RUNS`)."""
        prepare = PREPARED.get(act.kind) if act.kind not in self.program.kinds else None
        if prepare is not None:
            return prepare(self, act)
        handler, _ = self._handlers[act.id]

        def run(flow: Flow) -> bool:
            return handler(self, flow, act)

        return run

    def _fuse(self) -> dict[int, Chain]:
        """The fused chains of the program (fused.py): each activity whose prepared step a
        chain can hold, described once, and the chains of the activities a flow starts or
        goes on at after a step of its own (a start, an event, a fan-out, a Timer's end, the
        activity after one that is not fused)."""
        fusable = {}
        for aid, act in self._activities.items():
            spec = self._fusable(act)
            if spec is not None:
                fusable[aid] = spec
        program = self.program
        heads = [
            aid
            for aid, act in self._activities.items()
            if act.kind in _STARTS and act.panel == "Main" and aid not in program.inputs
        ]
        heads += [aid for aid, act in self._activities.items() if act.kind == K.INPUT_PIN]
        for aid, pins in self._outputs.items():
            on_its_own = aid not in fusable or self._activities[aid].kind == K.TIMER
            for links in pins.values():
                heads += [link.target for link in (links if on_its_own else links[1:])]
        for aid in (*self.compiled.sensors, *self.compiled.event_blocks):
            heads += [link.target for link in program.targets(aid)]
        for act in self._activities.values():
            if act.kind in (K.KEY_PRESS, K.KEY_RELEASE):
                heads += [link.target for link in program.targets(act.id)]
        scope = self._the_scope

        def through(fn: Callable[[Scope], Value], value: Value, state, frame: Frame) -> Value:
            """An expression's part run by its function, on the scope ``_scope`` fills."""
            scope.value = value
            scope.state = state
            scope.instance = frame.instance
            scope.parts = value if isinstance(value, dict) else None
            return fn(scope)

        helpers = {
            "ctl": self,
            "through": through,
            "want_bool": want_bool,
            "spawn": self._spawn,
            "command": self._command,
            "show": show,
            "convert": convert,
            "truth": _truth,
            "check_timer": _check_timer,
            "power": _power,
            "WheelPowers": WheelPowers,
            "first_sensor_value": first_sensor_value,
        }
        return fuse(fusable, dict.fromkeys(heads), helpers)

    def _fusable(self, act) -> Fusable | None:
        """What a chain needs to run ``act`` as its prepared step runs it (None: a chain
        cannot hold it; it runs by its own step)."""
        kind = act.kind
        pins = self._outputs.get(act.id, {})
        exprs = self._parsed.get(act.id, ())
        handler, _ = self._handlers[act.id]
        if kind in _PASS_ON or handler is ProgramController._pass_on:
            return Fusable("pass", (), pins)
        if kind == K.DATA and act.id in self.compiled.constants:
            return Fusable("data", (self.compiled.constants[act.id],), pins)
        if kind == K.VARIABLE:
            key = self._var_keys[act.id]
            if key in self.compiled.globals:
                return Fusable("variable", (key, self.compiled.globals[key][1]), pins)
        if kind == K.CALCULATE and exprs:
            return Fusable("calculate", (exprs[0],), pins)
        if kind == K.IF and exprs and len(exprs) == len(act.values):
            return Fusable("if", exprs, pins)
        if kind == K.TIMER:
            return Fusable("timer", (), pins)
        if kind == K.DRIVE and len(exprs) >= 2:
            return Fusable("drive", exprs[:2], pins)
        if kind == K.PRINT_LINE:
            return Fusable("print", (), pins)
        if kind == K.CODE:
            return Fusable("code", (), pins)
        return None

    def _sender(self, aid: int, pin: int) -> Send:
        """What :meth:`_go` does for the output ``pin`` of activity ``aid``, its links found
        once: the first target continues the flow, every other one starts a flow of its own."""
        out = self._outputs.get(aid)
        links = out.get(pin) if out else None
        if not links:
            return _send_nowhere
        first = links[0]
        target, in_pin = first.target, first.in_pin
        others = links[1:]
        if not others:

            def send_one(flow: Flow, value: Value) -> bool:
                flow.activity, flow.value, flow.in_pin = target, value, in_pin
                return True

            return send_one
        spawn = self._spawn

        def send_all(flow: Flow, value: Value) -> bool:
            for link in others:
                spawn(link.target, value, flow.frame, link.in_pin)
            flow.activity, flow.value, flow.in_pin = target, value, in_pin
            return True

        return send_all

    def _prepare_pass_on(self, act) -> Step:
        send = self._sender(act.id, 0)
        return lambda flow: send(flow, flow.value)

    def _prepare_data(self, act) -> Step:
        if act.id not in self.compiled.constants:
            return _uncompiled("its value")
        send = self._sender(act.id, 0)
        constant = self.compiled.constants[act.id]
        return lambda flow: send(flow, constant)

    def _prepare_variable(self, act) -> Step:
        key = self._var_keys[act.id]
        if key not in self.compiled.globals:
            return _uncompiled("its variable")
        vtype = self.compiled.globals[key][1]
        send = self._sender(act.id, 0)

        def run(flow: Flow) -> bool:
            stored = convert(flow.value, vtype)
            self.globals[key] = stored
            self.changes += 1
            return send(flow, stored)

        return run

    def _prepare_if(self, act) -> Step:
        exprs = self._exprs.get(act.id)
        if exprs is None or len(exprs) != len(act.values):
            return _uncompiled("its conditions")
        branches = tuple(
            (index, condition, self._sender(act.id, index)) for index, condition in enumerate(exprs)
        )
        otherwise = self._sender(act.id, ELSE)
        scope = self._scope

        def run(flow: Flow) -> bool:
            at = scope(flow)
            for index, condition, send in branches:
                truth = condition(at)
                if truth is True:
                    return send(flow, flow.value)
                if truth is not False:
                    _truth(truth, index)  # not true or false: the error
            return otherwise(flow, flow.value)

        return run

    def _prepare_timer(self, act) -> Step:
        send = self._sender(act.id, 0)

        def run(flow: Flow) -> bool:
            value = flow.value
            _check_timer(value)
            if not send(flow, value):
                return False  # nothing waits for the Timer
            raise _Sleep(max(0.0, float(value)) / 1000.0)

        return run

    def _prepare_drive(self, act) -> Step:
        exprs = self._exprs.get(act.id)
        if exprs is None or len(exprs) < 2:
            return _uncompiled("its wheel powers")
        left_power, right_power = exprs[0], exprs[1]
        send = self._sender(act.id, 0)
        scope = self._scope
        command = self._command

        def run(flow: Flow) -> bool:
            at = scope(flow)
            left = _power(left_power(at), "left")
            right = _power(right_power(at), "right")
            command(WheelPowers(left, right))
            return send(flow, flow.value)

        return run

    def _go(self, flow: Flow, pin: int, value: Value, source: int | None = None) -> bool:
        """Send ``value`` out of ``pin``: the first target continues this flow."""
        out = self._outputs.get(flow.activity if source is None else source)
        links = out.get(pin) if out else None
        if not links:
            return False
        for link in links[1:]:
            self._spawn(link.target, value, flow.frame, link.in_pin)
        first = links[0]
        flow.activity, flow.value, flow.in_pin = first.target, value, first.in_pin
        return True

    def _scope(self, flow: Flow) -> Scope:
        value = flow.value
        scope = self._the_scope
        scope.value = value
        scope.state = self.globals
        scope.instance = flow.frame.instance
        scope.parts = value if isinstance(value, dict) else None
        return scope

    def _expr(self, aid: int, index: int) -> Callable[[Scope], Value]:
        """The compiled expression ``index`` of activity ``aid``, as the function it runs."""
        exprs = self._exprs.get(aid)
        if exprs is not None and index < len(exprs):
            return exprs[index]
        return self.compiled.expr(aid, index).run

    # -- the handlers of the activity kinds: each runs the activity the flow is at and says
    # -- whether the flow goes on (it has moved the flow to the next activity)
    def _pass_on(self, flow: Flow, act) -> bool:
        return self._go(flow, 0, flow.value)

    def _never(self, flow: Flow, act) -> bool:
        return False  # a Comment, the Robot, a service mapped to "ignore": never run

    def _calculate(self, flow: Flow, act) -> bool:
        return self._go(flow, 0, self._expr(act.id, 0)(self._scope(flow)))

    def _switch(self, flow: Flow, act) -> bool:
        scope = self._scope(flow)
        value = flow.value
        expr = self.compiled.expr
        for index in range(len(act.values)):
            case = expr(act.id, index)(scope)
            if case is True or (not isinstance(case, bool) and case == value):
                return self._go(flow, index, value)
        return self._go(flow, ELSE, value)

    def _while(self, flow: Flow, act) -> bool:
        value = flow.value
        if _truth(self._expr(act.id, 0)(self._scope(flow)), 0):
            mark = (self.changes, _key(value))
            if flow.loops is None:
                flow.loops = {}
            elif flow.loops.get(act.id) == mark:
                raise _Park()
            flow.loops[act.id] = mark
            return self._go(flow, 0, value)
        if flow.loops is not None:
            flow.loops.pop(act.id, None)
        return self._go(flow, 0, value, self.program.loop_end[act.id])

    def _end_while(self, flow: Flow, act) -> bool:
        flow.activity = self.program.loop_start[act.id]
        return True

    def _break(self, flow: Flow, act) -> bool:
        loop = self.program.break_loop[act.id]
        if flow.loops is not None:
            flow.loops.pop(loop, None)
        return self._go(flow, 0, flow.value, self.program.loop_end[loop])

    def _print_line(self, flow: Flow, act) -> bool:
        self._print(show(flow.value))
        return self._go(flow, 0, flow.value)

    def _output_pin(self, flow: Flow, act) -> bool:
        frame = flow.frame
        if frame.block is None or frame.parent is None:
            return False
        flow.frame = frame.parent
        return self._go(flow, 0, flow.value, frame.block)

    def _event_pin(self, flow: Flow, act) -> bool:
        for aid, block in self.compiled.event_blocks.items():
            if block == flow.frame.panel:
                self._fired(aid, f"custom event {block}")
                for link in self.program.targets(aid):
                    self._spawn(link.target, flow.value, self._main, link.in_pin)
        return False

    def _code(self, flow: Flow, act) -> bool:
        return self._go(flow, 0, first_sensor_value(flow.value))

    # -- kinds a mapping file names (program/kinds.py): the argument, then the command
    def _argument(self, flow: Flow, act) -> Value:
        mapped = self.program.kinds[act.kind]
        if mapped.value is None:
            return flow.value
        return self.compiled.expr(act.id, mapped.value)(self._scope(flow))

    def _move_at_power(self, flow: Flow, act) -> bool:
        self._command(MoveAtPower(_power(self._argument(flow, act), "power")))
        return self._go(flow, 0, flow.value)

    def _turn_by_degrees(self, flow: Flow, act) -> bool:
        self._command(TurnByDegrees(_number(self._argument(flow, act), "degrees")))
        return self._go(flow, 0, flow.value)

    def _motor_left(self, flow: Flow, act) -> bool:
        self._command(MotorPower("left", _power(self._argument(flow, act), "left")))
        return self._go(flow, 0, flow.value)

    def _motor_right(self, flow: Flow, act) -> bool:
        self._command(MotorPower("right", _power(self._argument(flow, act), "right")))
        return self._go(flow, 0, flow.value)

    def _call(self, flow: Flow, act) -> bool:
        frame = flow.frame
        if frame.depth >= MAX_CALL_DEPTH:
            raise ValueError(f"activity blocks call each other more than {MAX_CALL_DEPTH} deep")
        instance = self._instance_defaults(act.name)
        scope = self._scope(flow)
        types = {v.name.lower(): v.type for v in self.program.panels[act.name].inputs}
        for index in range(1, len(act.values), 2):
            name = act.values[index - 1].strip().lower()
            if name:
                instance[name] = convert(self.compiled.expr(act.id, index)(scope), types[name])
        flow.frame = Frame(act.name, instance, act.id, frame, frame.depth + 1)
        entry = self.program.pin_of(act.name, K.INPUT_PIN)
        if entry is None:
            return False
        flow.activity = entry
        return True

    def _join(self, flow: Flow, act) -> bool:
        inputs = self.program.inputs.get(act.id, ())
        count = max(len(act.values), max((lk.in_pin for lk in inputs), default=0) + 1)
        # one Join per running block call, kept by the call so it goes with it; events at
        # panel level share the panel's Join
        joins = flow.frame.joins if flow.frame.block is not None else self._joins
        queues = joins.setdefault(act.id, [deque() for _ in range(count)])
        if len(queues[flow.in_pin]) >= MAX_JOIN_QUEUE:
            raise ValueError(f"more than {MAX_JOIN_QUEUE:,} messages wait at one Join input")
        queues[flow.in_pin].append(flow.value)
        self._join_parts += parts_of(flow.value)
        if not all(queues):
            return False
        names = [(act.value(i).strip() or f"input{i}").lower() for i in range(count)]
        parts = {name: q.popleft() for name, q in zip(names, queues, strict=True)}
        self._join_parts -= sum(parts_of(v) for v in parts.values())
        return self._go(flow, 0, join_message(parts))

    # -- limits --------------------------------------------------------------------------
    def _over_work(self) -> None:
        aid = max(self._hot, key=self._hot.__getitem__, default=self._ready[0].activity)
        limit = self.limits.second
        self._stop(
            aid,
            f"the program ran {self._second_steps:,} activities in one simulated second (at "
            f"most {limit:,}), most of them from here: a loop that never waits? (a Timer in "
            "the loop lets the robot move)",
        )

    def _check_memory(self) -> None:
        flows = list(itertools.chain(self._ready, self._parked, (f for *_, f in self._sleeping)))
        held = self._join_parts + sum(parts_of(f.value) for f in flows)
        if held <= self.limits.memory:
            return
        held += sum(parts_of(v) for v in self.globals.values())
        if held <= self.limits.memory:
            return
        where: dict[int, int] = {}
        for flow in flows:
            where[flow.activity] = where.get(flow.activity, 0) + parts_of(flow.value)
        for joins in self._all_joins():
            for aid, queues in joins.items():
                where[aid] = where.get(aid, 0) + sum(parts_of(v) for q in queues for v in q)
        aid = max(where, key=where.__getitem__)
        self._stop(
            aid,
            f"the program holds values of {held:,} parts written out (at most "
            f"{self.limits.memory:,}; {where[aid]:,} of them in messages on their way to this "
            "activity or waiting at it): does a loop make messages faster than they are used?",
        )

    def _all_joins(self) -> list[dict[int, list[deque[Value]]]]:
        frames = {id(f.frame): f.frame for f in self._ready}
        frames.update({id(f.frame): f.frame for f in self._parked})
        frames.update({id(f.frame): f.frame for *_, f in self._sleeping})
        out = [self._joins]
        for frame in frames.values():
            at: Frame | None = frame
            while at is not None:
                out.append(at.joins)
                at = at.parent
        return out

    def _stop(self, aid: int, message: str) -> None:
        """Stop the program for good at ``aid``: its flows and Joins dropped, the robot told
        to stop."""
        act = self.program.activities[aid]
        self.stopped = RunError(self.now, act.panel, aid, self.program.label(act), message)
        self.errors_total += 1
        if len(self.errors) >= MAX_ERRORS:
            self.errors.pop()
        self.errors.append(self.stopped)

    def _halted(self) -> list[Any]:
        self._ready.clear()
        self._parked = []
        self._sleeping = []
        self._joins = {}
        self._join_parts = 0
        self._pushed = []
        self._note_keys()
        self.commands = []
        self.state = "stopped"
        return [Stop()]

    # -- effects ---------------------------------------------------------------------------
    def _command(self, cmd: Any) -> None:
        self.commands.append(cmd)
        self.changes += 1

    def _print(self, text: str) -> None:
        self.changes += 1
        line = Printed(self.now, text[:1000])
        self.printed_total += 1
        self.recent.append(line)
        if len(self.printed) < MAX_PRINTED:
            self.printed.append(line)
        else:
            self.printed_dropped += 1

    def _error(self, aid: int, message: str) -> None:
        self.errors_total += 1
        if len(self.errors) < MAX_ERRORS:
            act = self.program.activities[aid]
            self.errors.append(RunError(self.now, act.panel, aid, self.program.label(act), message))


#: activity kind -> its handler (a flow at the activity: does the flow go on?)
RUNS: dict[int, Callable[[ProgramController, Flow, Any], bool]] = {
    K.CALCULATE: ProgramController._calculate,
    K.SWITCH: ProgramController._switch,
    K.WHILE: ProgramController._while,
    K.END_WHILE: ProgramController._end_while,
    K.BREAK: ProgramController._break,
    K.JOIN: ProgramController._join,
    K.PRINT_LINE: ProgramController._print_line,
    K.BLOCK: ProgramController._call,
    K.OUTPUT_PIN: ProgramController._output_pin,
    K.EVENT_PIN: ProgramController._event_pin,
    K.CODE: ProgramController._code,
    K.COMMENT: ProgramController._never,
    K.ROBOT: ProgramController._never,
}
#: what a kind named in a mapping file runs as (``program/kinds.py`` MAPPABLE): its handler
MAPPED_RUNS: dict[str, Callable[[ProgramController, Flow, Any], bool]] = {
    "move-at-power": ProgramController._move_at_power,
    "turn-by-degrees": ProgramController._turn_by_degrees,
    "motor-left": ProgramController._motor_left,
    "motor-right": ProgramController._motor_right,
    "custom-event": ProgramController._pass_on,
    "ignore": ProgramController._never,
}
#: the kinds whose steps are made once for each activity (see ProgramController._prepare),
#: the kinds most programs run at every report: kind -> what makes the step
PREPARED: dict[int, Callable[[ProgramController, Any], Step]] = {
    **dict.fromkeys(_PASS_ON, ProgramController._prepare_pass_on),
    K.DATA: ProgramController._prepare_data,
    K.VARIABLE: ProgramController._prepare_variable,
    K.IF: ProgramController._prepare_if,
    K.TIMER: ProgramController._prepare_timer,
    K.DRIVE: ProgramController._prepare_drive,
}
#: the handler of a kind no table names (the loader refuses such a kind: it never runs)
_NEVER_RUNS = ProgramController._never
#: sensor activity kind -> what it does with a report (the activity, its port, the readings)
SENSES: dict[int, Callable[[ProgramController, int, int, dict[int, Value]], None]] = {
    K.RAW_SENSOR: ProgramController._sense_raw,
    K.TOUCH: ProgramController._sense_touch,
    K.DISTANCE: ProgramController._sense_value,
    K.OTHER_SENSOR: ProgramController._sense_value,
}


def convert(value: Value, vtype: str) -> Value:
    """A value stored in a variable or parameter of a declared type (as C#'s Convert)."""
    if vtype == "System.String":
        return show(value)
    if isinstance(value, dict):
        raise ValueError("a Join message cannot be stored in a variable")
    if vtype in ("System.Int32", "System.Double"):
        if isinstance(value, str):
            try:
                value = float(value.strip()) if "." in value else int(value.strip())
            except ValueError:
                raise ValueError(f"{value[:30]!r} is not a number for a {vtype[7:]}") from None
        if isinstance(value, bool) or not isinstance(value, int | float):
            raise ValueError(f"{type_name(value)} cannot be stored in a {vtype[7:]}")
        if vtype == "System.Double":
            return float(value)
        whole = round(value)
        if not -INT_LIMIT <= whole < INT_LIMIT:
            raise LimitError("the number is past the range of a 64-bit whole number")
        return whole
    if vtype == "System.Boolean":
        if isinstance(value, str) and value.strip().lower() in ("true", "false"):
            return value.strip().lower() == "true"
        if not isinstance(value, bool):
            raise ValueError(f"{type_name(value)} cannot be stored in a Boolean")
    return value


def _port(ports: dict[str, int], name: str) -> int:
    """The port of a reading named ``port N`` (kept in ``ports`` for the next report)."""
    port = ports[name] = int(name.split()[-1])
    return port


def _uncompiled(what: str) -> Step:
    """The step of an activity whose compiled parts are missing (a program made without
    ``compile_program``, which refuses one): an error when it runs."""

    def run(flow: Flow) -> bool:
        raise ExprError(f"{what} did not compile")

    return run


def _single(aid: int, step: Step) -> Chain:
    """The chain of one activity run by its own step (see fused.py for what a chain
    returns)."""

    def chain(flow: Flow, room: int) -> int:
        try:
            goes_on = step(flow)
        except _Sleep as sleep:
            flow.wait = sleep.seconds
            return 1 | SLEEPS
        except _Park:
            return 1 | PARKS
        except BaseException:
            flow.activity, flow.ran = aid, 1  # the step may have moved the flow already
            raise
        return 1 if goes_on else 1 | ENDED

    return chain


def _send_nowhere(flow: Flow, value: Value) -> bool:
    return False  # no link leaves the pin: the flow ends


def _check_timer(value: Value) -> None:
    """A Timer waits a number of milliseconds (true and false are not numbers)."""
    if not isinstance(value, int | float) or isinstance(value, bool):
        raise ValueError(f"the Timer needs a number of milliseconds, not {type_name(value)}")


def _truth(value: Value, index: int) -> bool:
    if not isinstance(value, bool):
        raise ValueError(f"condition {index} gave {type_name(value)}, not true or false")
    return value


def _number(value: Value, what: str) -> float:
    if isinstance(value, bool) or not isinstance(value, int | float):
        raise ValueError(f"the {what} must be a number, not {type_name(value)}")
    return float(value)


def _power(value: Value, what: str) -> float:
    return _number(value, f"{what} power")


def _plain(value: Value) -> bool:
    return isinstance(value, int | float | str | bool)


def _key(value: Value) -> Any:
    if isinstance(value, JoinMessage):
        return tuple(sorted(value.items()))
    return (type(value), value)
