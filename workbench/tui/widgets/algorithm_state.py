"""The chosen algorithm and, while it runs, its state machine thinking: the states with the
current one highlighted, the variables, the last transition with the sensor values that fired
it, and a scrolling log of transitions."""

from __future__ import annotations

from textual.app import ComposeResult
from textual.containers import Vertical
from textual.content import Content
from textual.reactive import var
from textual.widgets import Static

from workbench.control.station import LabStation
from workbench.fsm.machine import FsmController
from workbench.sim.profiles import get_profile

from .kept_static import KeptStatic
from .text import arrow, named_title, number, set_border_title
from .transition_log import TransitionLog, values_text


class AlgorithmState(Vertical):
    """What the algorithm is doing, refreshed from the station after each tick."""

    DEFAULT_CSS = """
    AlgorithmState {
        height: 1fr;
        padding: 0 1;
        border-top: solid $primary;
        border-title-color: $text-primary;
    }
    AlgorithmState > Static {
        height: auto;
    }
    AlgorithmState > #algorithm-summary {
        color: $text-secondary;
    }
    AlgorithmState > #algorithm-last {
        color: $text-muted;
    }
    /* while it runs, the last transition has the rows most transitions take from the start */
    AlgorithmState.-running > #algorithm-last {
        min-height: 3;
    }
    """

    summary: var[str] = var("", init=False)
    states: var[tuple[tuple[str, ...], str | None]] = var(((), None), init=False)
    variables: var[str] = var("", init=False)
    last: var[str] = var("", init=False)

    def __init__(self, *, id: str | None = None, classes: str | None = None) -> None:
        super().__init__(id=id, classes=classes)
        set_border_title(self, "Algorithm")
        self._summary = Static(id="algorithm-summary", markup=False)
        self._states = KeptStatic(id="algorithm-states")
        self._vars = Static(id="algorithm-vars", markup=False)
        self._last = Static(id="algorithm-last", markup=False)
        self._log = TransitionLog(id="algorithm-log")
        #: whether the texts fit their rows to their length at once (see update_in_place)
        self._fit = True

    def compose(self) -> ComposeResult:
        yield self._summary
        yield self._states
        yield self._vars
        yield self._last
        yield self._log

    def on_mount(self) -> None:
        self.watch_summary(self.summary)
        self.watch_states(self.states)
        self.watch_variables(self.variables)
        self.watch_last(self.last)

    @property
    def highlighted(self) -> str | None:
        """The state shown as the current one (None when no algorithm runs)."""
        return self.states[1]

    def show(self, station: LabStation, unicode: bool) -> None:
        definition = station.algorithm
        running = station.driving.controller if station.driving is not None else None
        controller = running if isinstance(running, FsmController) else None
        unit = get_profile(station.profile).unit
        log = self._log
        # the texts keep the rows they took while the algorithm runs; they fit them again when
        # it is paused (frames come a step at a time then) or not running
        fit = controller is None or station.paused
        self.set_class(not fit, "-running")
        if fit != self._fit:
            # a run starts, pauses, goes on or ends: the screen is laid out again anyway, and
            # each text takes its own rows (those kept while it ran go back)
            for widget in (self._summary, self._states, self._vars, self._last):
                widget.refresh(layout=True)
        self._fit = fit
        if definition is None:
            set_border_title(self, "Algorithm")
            self.summary = "none chosen: the keys drive. g chooses one."
            self.states = ((), None)
            self.variables = ""
            self.last = ""
            log.show(None, (), unit, unicode)
            log.display = False
            return
        set_border_title(self, named_title(self, "Algorithm", definition.name))
        names = tuple(s.name for s in definition.states)
        if controller is None:
            missing = station.missing_sensors()
            if missing:
                first = missing.splitlines()[0].split(": add one")[0]
                self.summary = f"cannot start: {first}. f fits the sensors it needs."
            else:
                self.summary = "not running: x starts it, g changes it."
            self.states = (names, None)
            self.variables = ""
            self.last = ""
            log.display = False
            return
        t = station.session.world.time
        timer = controller.timer_remaining(t)
        self.summary = f"in {controller.state}" + (
            f", timer {timer:.1f} s" if timer is not None else ""
        )
        self.states = (names, controller.state)
        self.variables = " ".join(
            f"{k}={number(v, unit) if isinstance(v, int | float) else v}"
            for k, v in controller.variables.items()
        )
        history = controller.history
        if history:
            tr = history[-1]
            text = f"{tr.time:.1f} s {tr.source} {arrow(unicode)} {tr.target}"
            if tr.guard_text:
                text += f" when {tr.guard_text}"
            if tr.values:
                text += f" ({values_text(dict(tr.values), unit)})"
            self.last = text
        else:
            self.last = "no transition yet"
        log.display = True
        log.show(controller, history, unit, unicode)

    def watch_summary(self, text: str) -> None:
        # the timer counts down every tick: lay out again only when the height changes
        update_in_place(self._summary, text, self._fit)

    def watch_states(self, value: tuple[tuple[str, ...], str | None]) -> None:
        names, current = value
        parts = [
            Content.styled(f" {name} ", "bold reverse") if name == current else Content(f" {name} ")
            for name in names
        ]
        widget = self._states
        update_in_place(widget, Content("").join(parts), self._fit)
        widget.display = bool(names)

    def watch_variables(self, text: str) -> None:
        widget = self._vars
        update_in_place(widget, f"vars: {text}" if text else "", self._fit)
        widget.display = bool(text)

    def watch_last(self, text: str) -> None:
        widget = self._last
        update_in_place(widget, text, self._fit)
        widget.display = bool(text)


def update_in_place(widget: Static, content: str | Content, fit: bool = True) -> None:
    """Show ``content`` in ``widget``, laying the panel out again only when it takes another
    number of rows at the widget's width; with ``fit`` False (an algorithm running), only when
    it needs more: a shorter text keeps the rows it had, blank at the end. A new layout is most
    of a frame's work, and the state highlighted, the timer and the last transition change many
    times a minute: a panel that grew and shrank with each of them also jumped as it ran."""
    region = widget.content_region
    if not widget.is_mounted or not widget.display or region.width <= 0:
        widget.update(content)
        return
    widget.update(content, layout=False)
    size = widget.size
    rows = widget.get_content_height(size, size, region.width)
    if rows > region.height or (fit and rows != region.height):
        widget.refresh(layout=True)
