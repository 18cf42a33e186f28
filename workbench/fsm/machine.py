"""The FSM engine: one engine for the built-in algorithms and for student-written FSM files.

Entering a state runs its ``on_enter`` actions (motor commands, timers, variable assignments).
Every control tick the current state's transitions are checked top to bottom and the first whose
guard holds fires; at most one transition fires per tick. Timers run on simulated time. The
definition dataclasses, checks and sensor binding live in :mod:`workbench.fsm.definition` and
are re-exported here.
"""

from __future__ import annotations

from collections import deque
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field

from workbench.fsm.definition import (
    EVENTS,
    PROFILES,
    RESERVED,
    Action,
    FsmDefinition,
    FsmDefinitionError,
    FsmError,
    FsmRuntimeError,
    MotorAction,
    MoveAction,
    Parameter,
    ParameterError,
    Problem,
    SensorBindingError,
    SensorNeed,
    SetAction,
    State,
    StopAction,
    TimerAction,
    Transition,
    TransitionDef,
    TurnAction,
    Variable,
    WheelsAction,
    bind_sensors,
    check_definition,
    preset_sensors,
    resolve_params,
)
from workbench.fsm.expr import Expr, Fn, Value, compile_expr
from workbench.sim.commands import (
    Command,
    MotorPower,
    MoveAtPower,
    Stop,
    TurnByDegrees,
    WheelPowers,
)

__all__ = [
    "EVENTS",
    "PROFILES",
    "RESERVED",
    "Action",
    "FsmController",
    "FsmDefinition",
    "FsmDefinitionError",
    "FsmError",
    "FsmRuntimeError",
    "MotorAction",
    "MoveAction",
    "Parameter",
    "ParameterError",
    "Problem",
    "SensorBindingError",
    "SensorNeed",
    "SetAction",
    "State",
    "StopAction",
    "TimerAction",
    "Transition",
    "TransitionDef",
    "TurnAction",
    "Variable",
    "WheelsAction",
    "bind_sensors",
    "check_definition",
    "preset_sensors",
    "resolve_params",
]

_TIMER_SLACK = 1e-9


@dataclass
class _Rule:
    guard: Fn | None
    text: str
    reads: tuple[str, ...]
    target: str
    assigns: list[tuple[str, Fn]]
    state: _Node | None = None


@dataclass
class _Node:
    name: str
    actions: list[tuple[str, object, str]]
    rules: list[_Rule] = field(default_factory=list)


class FsmController:
    """Runs one :class:`FsmDefinition` with resolved parameters for one profile.

    ``start(t)`` enters the initial state; ``tick(t, readings, events)`` is called every control
    tick with sensor readings keyed by sensor name and world events (``"turn_done"``). Both
    return the motor commands to apply, usually none.
    """

    def __init__(
        self,
        definition: FsmDefinition,
        params: Mapping[str, float] | None = None,
        profile: str = "unity",
        history_size: int = 50,
    ) -> None:
        problems = check_definition(definition)
        if problems:
            raise FsmDefinitionError(definition.name, problems)
        self.definition = definition
        self.profile = profile
        self.params = resolve_params(definition, profile, params)
        self.history: deque[Transition] = deque(maxlen=history_size)
        self._sensor_names = frozenset(s.name for s in definition.sensors)
        self._var_names = tuple(v.name for v in definition.variables)
        names = definition.runtime_names()
        self._initial_vars = [
            (v.name, compile_expr(v.initial, None, self.params)) for v in definition.variables
        ]
        self._nodes = {s.name: self._compile_state(s, names) for s in definition.states}
        for node in self._nodes.values():
            for rule in node.rules:
                rule.state = self._nodes[rule.target]
        self._env: dict[str, Value] = {}
        self.reset()

    # -- public ------------------------------------------------------------------------

    @property
    def state(self) -> str:
        return self._current.name

    @property
    def variables(self) -> dict[str, Value]:
        env = self._env
        return {name: env[name] for name in self._var_names}

    @property
    def started(self) -> bool:
        return self._started

    def timer_remaining(self, t: float) -> float | None:
        """Seconds left on the current state's timer, or None when no timer runs."""
        if self._deadline is None:
            return None
        return max(0.0, self._deadline + _TIMER_SLACK - t)

    def reset(self) -> None:
        """Back to the initial state, not yet entered: variables, timer and history cleared."""
        env = self._env
        env.clear()
        env.update(self.params)
        for name in self._sensor_names:
            env[name] = None  # type: ignore[assignment]
        for event in EVENTS:
            env[event] = False
        for name, expr in self._initial_vars:
            env[name] = expr(env)
        self._current = self._nodes[self.definition.initial]
        self._deadline: float | None = None
        self._unseen = set(self._sensor_names)
        self._started = False
        self.history.clear()

    def start(self, t: float = 0.0) -> list[Command]:
        """Reset and enter the initial state; returns its ``on_enter`` commands."""
        self.reset()
        self._started = True
        out: list[Command] = []
        self._enter(self._current, t, out)
        return out

    def tick(
        self,
        t: float,
        readings: Mapping[str, float],
        events: frozenset[str] = frozenset(),
    ) -> list[Command]:
        env = self._env
        env.update(readings)
        if self._unseen:
            self._first_readings(readings)
        if events:
            for event in events:
                if event in EVENTS:
                    env[event] = True
        deadline = self._deadline
        if deadline is not None and t >= deadline:
            self._deadline = None
            env["timer_done"] = True
        rule = None
        try:
            for rule in self._current.rules:
                guard = rule.guard
                if guard is None or guard(env):
                    return self._fire(rule, t)
        except (ArithmeticError, TypeError, ValueError, KeyError) as exc:
            text = rule.text if rule is not None else ""
            raise self._failure(f"guard {text!r}", exc) from exc
        return []

    # -- internals -----------------------------------------------------------------------

    def _first_readings(self, readings: Mapping[str, float]) -> None:
        if not self._started:
            raise FsmRuntimeError(f"{self.definition.name}: call start() before tick()")
        strangers = set(readings) - self._sensor_names
        if strangers:
            raise FsmRuntimeError(
                f"{self.definition.name}: readings for unknown sensor name(s) "
                f"{_listing(str(s) for s in strangers)}; this FSM reads "
                f"{_listing(self._sensor_names)} (map ports to names with bind_sensors)"
            )
        self._unseen -= set(readings)
        if self._unseen:
            raise FsmRuntimeError(
                f"{self.definition.name}: no reading for sensor(s) "
                f"{', '.join(sorted(self._unseen))}: readings must be keyed by sensor name "
                f"({_listing(self._sensor_names)})"
            )

    def _fire(self, rule: _Rule, t: float) -> list[Command]:
        env = self._env
        source = self._current.name
        values = {name: env.get(name) for name in rule.reads}
        try:
            for name, fn in rule.assigns:
                env[name] = fn(env)
        except (ArithmeticError, TypeError, ValueError, KeyError) as exc:
            raise self._failure(f"set: on the transition to {rule.target}", exc) from exc
        self.history.append(Transition(t, source, rule.target, rule.text, values))
        out: list[Command] = []
        self._enter(rule.state, t, out)  # type: ignore[arg-type]
        return out

    def _enter(self, node: _Node, t: float, out: list[Command]) -> None:
        env = self._env
        self._current = node
        self._deadline = None
        env["turn_done"] = False
        env["timer_done"] = False
        action: tuple[str, object, str] = ("", None, "")
        try:
            for action in node.actions:
                kind, fn, _ = action
                if kind == "cmd":
                    out.append(fn(env))  # type: ignore[operator]
                elif kind == "timer":
                    seconds = float(fn(env))  # type: ignore[operator]
                    self._deadline = t + max(0.0, seconds) - _TIMER_SLACK
                else:
                    for name, f in fn:  # type: ignore[attr-defined]
                        env[name] = f(env)
        except (ArithmeticError, TypeError, ValueError, KeyError) as exc:
            raise self._failure(f"on_enter action {action[2]}", exc) from exc

    def _failure(self, what: str, exc: Exception) -> FsmRuntimeError:
        reason = exc.args[0] if isinstance(exc, KeyError) and exc.args else exc
        if isinstance(exc, KeyError):
            reason = f"no value for {reason!r}"
        return FsmRuntimeError(
            f"{self.definition.name}, state {self._current.name}: {what} failed: {reason}"
        )

    def _compile_state(self, state: State, names: set[str]) -> _Node:
        node = _Node(state.name, [self._compile_action(a, names) for a in state.on_enter])
        for tr in state.transitions:
            guard: Expr | None = self._expr(tr.when, names) if tr.when else None
            fn = None
            if guard is not None and guard.constant:
                if not guard(None):
                    continue
            elif guard is not None:
                fn = guard.evaluate
            reads = tuple(sorted(guard.names)) if guard is not None else ()
            assigns = [(var, self._expr(text, names).evaluate) for var, text in tr.set]
            node.rules.append(_Rule(fn, tr.when, reads, tr.target, assigns))
        return node

    def _compile_action(self, action: Action, names: set[str]) -> tuple[str, object, str]:
        ev = lambda text: self._expr(text, names).evaluate  # noqa: E731
        if isinstance(action, WheelsAction):
            lf, rf = ev(action.left), ev(action.right)
            return ("cmd", lambda env: WheelPowers(float(lf(env)), float(rf(env))), "wheels")
        if isinstance(action, MotorAction):
            wheel, pf = action.wheel, ev(action.power)
            return ("cmd", lambda env: MotorPower(wheel, float(pf(env))), "motor")
        if isinstance(action, MoveAction):
            mf = ev(action.power)
            return ("cmd", lambda env: MoveAtPower(float(mf(env))), "move")
        if isinstance(action, TurnAction):
            tf = ev(action.degrees)
            return ("cmd", lambda env: TurnByDegrees(float(tf(env))), "turn")
        if isinstance(action, StopAction):
            return ("cmd", lambda env: Stop(), "stop")
        if isinstance(action, TimerAction):
            return ("timer", ev(action.seconds), "timer")
        pairs = [(var, ev(text)) for var, text in action.assignments]
        return ("set", pairs, "set")

    def _expr(self, text: str, names: set[str]) -> Expr:
        return compile_expr(text, names, self.params)


def _listing(names: Iterable[str]) -> str:
    return ", ".join(sorted(names)) or "no sensors"
