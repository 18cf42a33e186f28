"""The algorithm selector: pick a built-in or load a YAML FSM file or a VIPLE program, read what
it does and what it needs, tune its parameters, and start, pause, step or reset it.

An FSM file with problems is reported as ``file:line:column: message``; a VIPLE program's
problems are listed all at once, as the loader words them, in the scrolling details. A missing
sensor is explained, with a one-key fix for algorithms: ``f`` gives the robot the sensors the
algorithm reads.
"""

from __future__ import annotations

import asyncio
from pathlib import Path
from typing import ClassVar

from textual import on
from textual.app import ComposeResult
from textual.binding import BindingType
from textual.containers import Horizontal, Vertical, VerticalScroll
from textual.screen import ModalScreen
from textual.widgets import Button, Input, Label, OptionList, Static
from textual.widgets.option_list import Option

from workbench.control.station import LabStation, ProgramChoice
from workbench.files.workspace import OutsideWorkspace
from workbench.fsm.algorithms import ALGORITHM_DIR, list_algorithms
from workbench.fsm.machine import FsmError, resolve_params
from workbench.fsm.yaml_file import FsmFileError
from workbench.program.choice import is_program_path, load_choice
from workbench.program.problems import ProgramError
from workbench.sim.sensors import SensorConfigError
from workbench.sim.session import Snapshot

from ..host import OpenScreen, Say, ShowsSnapshot, StationChanged
from ..keys import bindings
from ..plain import drawn_in_unicode, prose
from ..widgets.field import Field
from ..widgets.param_editor import ParamEditor


def _source(source: str) -> str:
    """ "built-in" for the bundled algorithms, else the file as given."""
    if not source:
        return "built-in"
    path = Path(source)
    if path.parent.resolve() == ALGORITHM_DIR:
        return "built-in"
    return source


class AlgorithmModal(ShowsSnapshot, ModalScreen[None]):
    """Choose and set up the algorithm that drives the robot."""

    DEFAULT_CSS = """
    AlgorithmModal {
        align: center middle;
    }
    AlgorithmModal > #alg-dialog {
        width: 100%;
        max-width: 110;
        height: 100%;
        max-height: 36;
        border: round $primary;
        border-title-color: $text-primary;
        border-subtitle-color: $text-muted;
        background: $surface;
        padding: 0 1;
    }
    AlgorithmModal #alg-top {
        height: 1fr;
    }
    AlgorithmModal #alg-choose {
        width: 27;
        margin-right: 1;
    }
    AlgorithmModal #alg-builtins {
        height: auto;
        max-height: 10;
        border: none;
        padding: 0;
        margin-bottom: 1;
        scrollbar-size-vertical: 1;
    }
    AlgorithmModal .heading {
        color: $text-primary;
        text-style: bold;
    }
    AlgorithmModal #alg-path {
        margin: 0;
    }
    AlgorithmModal #alg-file-buttons {
        height: 1;
    }
    AlgorithmModal #alg-file-buttons Button {
        margin-right: 1;
    }
    AlgorithmModal Button {
        min-width: 0;
        width: auto;
    }
    AlgorithmModal #alg-details {
        width: 1fr;
        scrollbar-size-vertical: 1;
    }
    AlgorithmModal #alg-details > Static {
        height: auto;
        margin-bottom: 1;
    }
    AlgorithmModal #alg-missing {
        color: $text-warning;
    }
    AlgorithmModal #alg-problems {
        color: $text-error;
    }
    AlgorithmModal #alg-params {
        height: auto;
        margin-bottom: 1;
    }
    AlgorithmModal #alg-description {
        color: $text-muted;
    }
    AlgorithmModal #alg-params-head {
        height: 1;
    }
    AlgorithmModal #alg-params-head Label {
        width: 1fr;
    }
    AlgorithmModal #alg-error {
        height: auto;
        max-height: 6;
        color: $text-error;
    }
    AlgorithmModal #alg-buttons {
        height: 1;
    }
    AlgorithmModal #alg-buttons Button {
        margin-right: 1;
    }
    AlgorithmModal #alg-live {
        width: 1fr;
        text-align: right;
        color: $text-muted;
    }
    """

    BINDINGS: ClassVar[list[BindingType]] = [
        *bindings("dialog.close", "algorithm.fix", "algorithm.defaults", "algorithm.edit")
    ]

    def __init__(self, station: LabStation) -> None:
        super().__init__()
        self.station = station
        self._ready = False

    # -- layout ----------------------------------------------------------------------------
    def compose(self) -> ComposeResult:
        dialog = Vertical(id="alg-dialog")
        dialog.border_title = "Algorithm"
        dialog.border_subtitle = "enter picks, f fits sensors, E edits, escape closes"
        names = list_algorithms()
        with dialog:
            with Horizontal(id="alg-top"):
                with Vertical(id="alg-choose"):
                    yield Label("Built-in", classes="heading")
                    yield OptionList(*[Option(n, id=n) for n in names], id="alg-builtins")
                    yield Label("File: FSM or VIPLE", classes="heading")
                    files = self.station.files
                    example = "~/my.yaml or ~/my.viple" if files.confined else "fsm.yaml, x.viple"
                    yield Field(placeholder=example, compact=True, id="alg-path")
                    with Horizontal(id="alg-file-buttons"):
                        yield Button("Load file", compact=True, id="alg-load")
                        yield Button("Edit", compact=True, id="alg-edit")
                with VerticalScroll(id="alg-details"):
                    yield Static(id="alg-title", markup=False)
                    yield Static(id="alg-problems", markup=False)
                    yield Static(id="alg-missing", markup=False)
                    yield Static(id="alg-sensors", markup=False)
                    with Horizontal(id="alg-params-head"):
                        yield Label("Parameters", classes="heading")
                        yield Button("Defaults", compact=True, id="alg-defaults")
                    yield Vertical(id="alg-params")
                    yield Static(id="alg-description", markup=False)
            yield Static(id="alg-error", markup=False)
            with Horizontal(id="alg-buttons"):
                yield Button("Start", variant="primary", compact=True, id="alg-start")
                yield Button("Pause", compact=True, id="alg-pause")
                yield Button("Step", compact=True, id="alg-step")
                yield Button("Reset", compact=True, id="alg-reset")
                yield Button("Fit sensors", compact=True, id="alg-fix")
                yield Button("Close", compact=True, id="alg-close")
                yield Label("", id="alg-live", markup=False)

    async def on_mount(self) -> None:
        self._ready = True
        options = self.query_one("#alg-builtins", OptionList)
        current = self.station.algorithm
        names = list_algorithms()
        if self.station.program is not None:
            self.query_one("#alg-path", Input).value = self.station.program.source
            options.highlighted = 0
        elif current is not None and _source(current.source) == "built-in":
            options.highlighted = names.index(current.name)
        elif current is not None and current.source:
            self.query_one("#alg-path", Input).value = self.station.files.shown(current.source)
            options.highlighted = 0
        else:
            options.highlighted = 0
        options.focus()
        await self._show_definition()
        self.show_snapshot(self.station.snapshot())

    # -- drawing -------------------------------------------------------------------------------
    async def _show_definition(self) -> None:
        station = self.station
        definition = station.algorithm
        params = self.query_one("#alg-params", Vertical)
        await params.remove_children()
        title = self.query_one("#alg-title", Static)
        self.query_one("#alg-problems", Static).display = False
        self.query_one("#alg-params-head").display = definition is not None
        if station.program is not None:
            self._show_program()
            return
        if definition is None:
            title.update("No algorithm chosen: pick a built-in on the left, or load a YAML file.")
            for name in ("#alg-description", "#alg-sensors", "#alg-missing"):
                self.query_one(name, Static).display = False
            return
        title.update(f"{definition.name}  ({_source(definition.source)})")
        description = self.query_one("#alg-description", Static)
        text = " ".join(definition.description.split()) or "(no description)"
        description.update(prose(text, drawn_in_unicode(self)))
        description.display = True
        lines = [f"Sensors it reads ({station.profile} ports):"]
        lines += [
            f"  {need.name}: {need.kind} sensor mounted {need.mount}, "
            f"port {need.ports.get(station.profile, '?')}"
            for need in definition.sensors
        ]
        if not definition.sensors:
            lines.append("  none")
        sensors = self.query_one("#alg-sensors", Static)
        sensors.update("\n".join(lines))
        sensors.display = True
        self._show_missing()
        values = station.params()
        defaults = resolve_params(definition, station.profile)
        await params.mount_all(
            ParamEditor(p, values[p.name], defaults[p.name]) for p in definition.parameters
        )
        if not definition.parameters:
            await params.mount(Label("none", markup=False))

    def _show_program(self) -> None:
        station = self.station
        choice = station.program
        assert choice is not None
        self.query_one("#alg-params-head").display = False
        self.query_one("#alg-title", Static).update(f"{choice.name}  (VIPLE program)")
        sensors = self.query_one("#alg-sensors", Static)
        sensors.update("\n".join(choice.summary))
        sensors.display = True
        description = self.query_one("#alg-description", Static)
        description.update(
            "Start (or x) runs it from the start block. While it drives, w a s d, the arrows "
            "and the digits go to its Key Press events, and a key counts as released 0.75 s "
            "after it stops repeating. Space stops it."
        )
        description.display = True
        missing = choice.needs(station.sensors)
        widget = self.query_one("#alg-missing", Static)
        if missing:
            widget.update(f"{missing}\n\nSet the sensor ports (o) to the ones it reads.")
        widget.display = bool(missing)
        self.query_one("#alg-fix", Button).disabled = True

    async def _show_problems(self, path: str, problems: list[str]) -> None:
        """A program that did not load: every problem, in the scrolling details."""
        await self._show_definition()
        count = len(problems)
        self.query_one("#alg-title", Static).update(
            f"{path}: {count} problem{'s' if count != 1 else ''}; the program was not loaded"
        )
        widget = self.query_one("#alg-problems", Static)
        widget.update("\n".join(problems))
        widget.display = True
        for name in ("#alg-description", "#alg-sensors", "#alg-missing"):
            self.query_one(name, Static).display = False
        self.query_one("#alg-params-head").display = False
        await self.query_one("#alg-params", Vertical).remove_children()
        self.query_one("#alg-details", VerticalScroll).scroll_home(animate=False)

    def _show_missing(self) -> None:
        missing = self.station.missing_sensors()
        widget = self.query_one("#alg-missing", Static)
        if missing:
            why = "\n".join(line.split(": add one")[0] for line in missing.splitlines())
            widget.update(
                f"{why}\n\nPress f (or Fit sensors) to give the robot the sensors "
                "this algorithm reads."
            )
        widget.display = bool(missing)
        self.query_one("#alg-fix", Button).disabled = not missing

    def show_snapshot(self, snapshot: Snapshot) -> None:
        if not self._ready:
            return  # the app ticks while the dialog is still being built
        station = self.station
        paused = " (paused)" if station.paused else ""
        driving = station.driving
        if driving is None:
            text = f"driver: {snapshot.driver}{paused}"
        elif station.program_drives:
            text = f"program running, {driving.controller.state}{paused}"
        else:
            text = f"running, in {driving.controller.state}{paused}"
        self.query_one("#alg-live", Label).update(text)
        self.query_one("#alg-pause", Button).label = "Resume" if station.paused else "Pause"

    def _error(self, text: str) -> None:
        self.query_one("#alg-error", Static).update(text)

    def _refresh_all(self) -> None:
        self.show_snapshot(self.station.snapshot())
        self.post_message(StationChanged())

    # -- choosing ---------------------------------------------------------------------------------
    async def choose(self, name_or_path: str | Path) -> bool:
        """Select an algorithm on the station; a bad file's problems are shown, not raised."""
        if is_program_path(str(name_or_path)):
            return await self.choose_program(str(name_or_path))
        try:
            definition = self.station.select_algorithm(name_or_path)
        except FsmFileError as exc:
            self._error("\n".join(str(p) for p in exc.problems))
            return False
        except (FsmError, OSError, OutsideWorkspace) as exc:
            self._error(str(exc))
            return False
        self._error("")
        await self._show_definition()
        self._refresh_all()
        self.post_message(Say(f"chose {definition.name}: Start (or x) runs it"))
        return True

    async def choose_program(self, path: str) -> bool:
        """Load a VIPLE program to drive; a bad one's problems are all shown, not raised. The
        file is read and checked beside the event loop, so the app answers meanwhile."""
        self._error(f"loading {path}...")
        try:
            choice = await asyncio.to_thread(load_choice, self.station, path)
        except ProgramError as exc:
            await self._show_problems(path, [str(p) for p in exc.problems])
            self._error("fix these in VIPLE (or the file) and load it again")
            return False
        except (OSError, OutsideWorkspace) as exc:
            self._error(str(exc))
            return False
        self.station.use_program(choice)
        self._error("")
        await self._show_definition()
        self._refresh_all()
        self.post_message(Say(f"chose the program {choice.name}: Start (or x) runs it"))
        return True

    @on(OptionList.OptionSelected, "#alg-builtins")
    async def _builtin_selected(self, event: OptionList.OptionSelected) -> None:
        assert event.option.id is not None
        await self.choose(event.option.id)

    @on(Button.Pressed, "#alg-load")
    @on(Input.Submitted, "#alg-path")
    async def _load_file(self) -> None:
        text = self.query_one("#alg-path", Input).value.strip()
        if not text:
            self._error("type the path of a YAML FSM file or a VIPLE program first")
            return
        if await self.choose(text):
            # the path is done with: the dialog's keys (f fits the sensors) act on the dialog
            self.query_one("#alg-start", Button).focus()

    @on(Button.Pressed, "#alg-edit")
    def _edit_file(self) -> None:
        """The FSM editor on the file typed (else the chosen algorithm's, else a new one)."""
        self.action_edit_fsm()

    def action_edit_fsm(self) -> None:
        typed = self.query_one("#alg-path", Input).value.strip()
        if typed and is_program_path(typed):
            self._error("a VIPLE program is edited in VIPLE: the FSM editor takes YAML files")
            return
        self.dismiss()
        self.post_message(OpenScreen("fsm", typed))

    @on(ParamEditor.Edited)
    def _param_edited(self, event: ParamEditor.Edited) -> None:
        try:
            self.station.set_params([event.item])
        except (FsmError, ValueError) as exc:
            event.editor.set_error(str(exc))
            return
        event.editor.set_error(None)

    # -- actions ----------------------------------------------------------------------------------
    def action_start(self) -> None:
        station = self.station
        program = station.program is not None
        if not program and not self._algorithm_ready():
            return
        try:
            station.start()
        except (FsmError, ValueError) as exc:
            # a program's missing sensors take a line each: the first says enough here
            self._error(f"cannot start: {exc.args[0].splitlines()[0] if program else exc}")
            return
        self.post_message(Say(""))
        self._refresh_all()
        self.dismiss()

    def _algorithm_ready(self) -> bool:
        """The chosen algorithm can start; else the dialog says what to do first."""
        station = self.station
        if station.algorithm is None:
            self._error("pick an algorithm first")
            return False
        bad = [e.parameter.name for e in self.query(ParamEditor) if e.invalid]
        if bad:
            self._error(f"fix the parameters marked in red first: {', '.join(bad)}")
            return False
        if station.missing_sensors():
            self._error("the robot lacks a sensor this algorithm reads: press f to fit them")
            return False
        return True

    def action_pause(self) -> None:
        self.station.toggle_pause()
        self._refresh_all()

    def action_step(self) -> None:
        station = self.station
        station.pause()
        station.step(station.session.every)
        self._refresh_all()

    def action_reset(self) -> None:
        self.station.reset_robot()
        self.post_message(Say(""))
        self._refresh_all()

    def action_fix_sensors(self) -> None:
        station = self.station
        program = station.program
        if program is not None:
            self._fit_program(program)
            return
        if station.algorithm is None:
            self._error("choose an algorithm or load a program first: f fits its sensors")
            return
        if station.missing_sensors() is None:
            self._error(f"the robot has the sensors {station.algorithm.name} reads already")
            return
        station.apply_algorithm_preset()
        ports = ", ".join(str(s) for s in station.sensors)
        self._error("")
        self.post_message(Say(f"sensors set for {station.algorithm.name}: {ports}"))
        self._show_missing()
        self._refresh_all()

    def _fit_program(self, program: ProgramChoice) -> None:
        """Give the robot the sensors the program's diagram reads, or say what cannot be."""
        station = self.station
        if program.needs(station.sensors) is None:
            self._error(f"the robot has the sensors {program.name} reads already")
            return
        assert program.fit is not None
        fitted, cannot = program.fit(station.sensors)
        try:
            station.apply_sensors(fitted)
        except SensorConfigError as exc:
            self._error(f"cannot fit the sensors {program.name} reads: {exc}")
            return
        ports = ", ".join(str(s) for s in station.sensors)
        self._error(f"cannot fit all it reads: {cannot}" if cannot else "")
        self.post_message(Say(f"sensors set for {program.name}: {ports}"))
        self._refresh_all()

    async def action_defaults(self) -> None:
        if self.station.algorithm is None:
            return
        self.station.reset_params()
        await self._show_definition()

    def action_close(self) -> None:
        self.dismiss()

    @on(Button.Pressed, "#alg-buttons Button")
    async def _button(self, event: Button.Pressed) -> None:
        action = (event.button.id or "").removeprefix("alg-")
        if action == "close":
            self.dismiss()
        elif action in ("start", "pause", "step", "reset", "fix"):
            await self.run_action(action)

    @on(Button.Pressed, "#alg-defaults")
    async def _defaults(self) -> None:
        await self.action_defaults()
