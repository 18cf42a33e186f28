"""The VIPLE program chosen to drive and, while it runs, what it is doing: the flows' current
activities (panel and activity), the global variables, the last events it answered, and a
console of what its Print Lines printed (newest at the bottom)."""

from __future__ import annotations

from textual.app import ComposeResult
from textual.containers import Vertical
from textual.reactive import var
from textual.widgets import Log, Static

from workbench.control.station import LabStation
from workbench.program.interp import ProgramController
from workbench.program.viple_expr import show

from .text import named_title, set_border_title

#: how many flows and events the panel lists (the rest are counted)
SHOWN_FLOWS = 3
SHOWN_EVENTS = 2


class ProgramState(Vertical):
    """What the program is doing, refreshed from the station after each tick."""

    DEFAULT_CSS = """
    ProgramState {
        height: 1fr;
        padding: 0 1;
        border-top: solid $primary;
        border-title-color: $text-primary;
    }
    ProgramState > Static {
        height: auto;
    }
    ProgramState > #program-summary {
        color: $text-secondary;
    }
    ProgramState > #program-events {
        color: $text-muted;
    }
    ProgramState > #program-console {
        height: 1fr;
        min-height: 2;
        padding: 0;
        background: transparent;
        scrollbar-size-vertical: 1;
        overflow-x: hidden;
        border-top: dashed $panel;
    }
    """

    summary: var[str] = var("", init=False)
    flows: var[str] = var("", init=False)
    variables: var[str] = var("", init=False)
    events: var[str] = var("", init=False)

    def __init__(self, *, id: str | None = None, classes: str | None = None) -> None:
        super().__init__(id=id, classes=classes)
        set_border_title(self, "Program")
        self._summary = Static(id="program-summary", markup=False)
        self._flows = Static(id="program-flows", markup=False)
        self._vars = Static(id="program-vars", markup=False)
        self._events = Static(id="program-events", markup=False)
        self._log = Log(max_lines=200, id="program-console")
        self._run: object = None
        self._printed = 0

    def compose(self) -> ComposeResult:
        yield self._summary
        yield self._flows
        yield self._vars
        yield self._events
        yield self._log

    def on_mount(self) -> None:
        for name in ("summary", "flows", "variables", "events"):
            getattr(self, f"watch_{name}")(getattr(self, name))

    @property
    def console_lines(self) -> list[str]:
        """The console's lines, oldest first (what a student reads there)."""
        return list(self._log.lines)

    def show(self, station: LabStation, all_keys: bool = False) -> None:
        """Follow the station's program; ``all_keys``: every key goes to it (ctrl+k)."""
        choice = station.program
        run = station.driving.controller if station.driving is not None else None
        set_border_title(self, named_title(self, "Program", choice.name) if choice else "Program")
        if not isinstance(run, ProgramController):
            self.summary = "not running: x starts it, g changes it." if choice else ""
            self.flows = self.variables = self.events = ""
            return
        if run is not self._run:  # a new run: a fresh console
            self._run = run
            self._printed = 0
            self._log.clear()
        held = "+".join(sorted(run.held))
        holds = f", holds {held}" if held else ""
        if all_keys:
            self.summary = f"ALL KEYS go to it{holds} (^k: back)"
        else:
            self.summary = f"running{holds} (^k: all keys)"
        self.flows = _flows(run)
        self.variables = " ".join(f"{name}={_value(v)}" for name, v in run.variables.items())
        self.events = "\n".join(f"{f.time:5.1f} s {f.what}" for f in run.fired[-SHOWN_EVENTS:])
        self._follow_console(run)

    def _follow_console(self, run: ProgramController) -> None:
        new = run.printed_total - self._printed
        if new <= 0:
            return
        self._printed = run.printed_total
        lines = list(run.recent)[-new:]
        self._log.write_lines(f"{p.time:5.1f} {p.text}" for p in lines)

    def watch_summary(self, text: str) -> None:
        self._summary.update(text)
        self._summary.display = bool(text)

    def watch_flows(self, text: str) -> None:
        self._flows.update(text)
        self._flows.display = bool(text)

    def watch_variables(self, text: str) -> None:
        self._vars.update(f"vars: {text}" if text else "")
        self._vars.display = bool(text)

    def watch_events(self, text: str) -> None:
        self._events.update(text)
        self._events.display = bool(text)


def _flows(run: ProgramController) -> str:
    running = run.running(limit=SHOWN_FLOWS + 1)
    lines = [f"{panel}: {label}" + ("" if what == "ready" else f" ({what})")
             for panel, label, what in running[:SHOWN_FLOWS]]  # fmt: skip
    if len(running) > SHOWN_FLOWS:
        lines.append("...")
    return "\n".join(lines) if lines else "idle: waiting for events"


def _value(value: object) -> str:
    """A global as the panel shows it: reals to four figures, the rest as VIPLE prints them."""
    if isinstance(value, float):
        return f"{value:.4g}"
    return show(value)
