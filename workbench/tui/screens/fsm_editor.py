"""The FSM editor: a student's state machine as YAML text, its problems as they type, its
diagram beside it, forms for beginners, save, and run it at once on the station.

The text is the ``TextArea``'s (with its undo history, kept across saves); the file, the
checks, the forms' edits and the diagram's layout are the core's
(:mod:`workbench.fsm.editing`, :mod:`~workbench.fsm.forms`,
:mod:`~workbench.fsm.diagram`). Every change is checked a moment after the typing
stops, in a thread, so a large file never holds the screen. Below 100 columns the text and
the diagram share the space: ctrl+t shows one or the other.
"""

from __future__ import annotations

import asyncio
from collections.abc import Callable
from pathlib import Path
from typing import ClassVar

from rich.text import Text
from textual import on
from textual.app import ComposeResult
from textual.binding import BindingType
from textual.containers import Horizontal, VerticalScroll
from textual.events import Resize
from textual.screen import Screen
from textual.timer import Timer
from textual.widgets import Static, TextArea

from workbench.control.station import LabStation
from workbench.files.workspace import OutsideWorkspace
from workbench.fsm.diagram import Diagram, layout, state_notes
from workbench.fsm.editing import Checked, FsmDraft, FsmEditError, check
from workbench.fsm.forms import Edited, new_text
from workbench.fsm.machine import FsmController, FsmError
from workbench.fsm.yaml_file import FsmFileError
from workbench.sim.session import Snapshot

from ..dialogs.fsm_form import FORMS, FormDialog
from ..dialogs.path import PathDialog
from ..dialogs.unsaved import Choice, UnsavedDialog
from ..host import FollowsUnicode, ShowsSnapshot, StationChanged
from ..keys import FSM_EDITOR_KEY_IDS, bindings
from ..serving.single_layout import SingleLayout
from ..widgets.key_bar import KeyBar

#: seconds after the last key before the text is checked
CHECK_DELAY = 0.3
#: the narrowest screen that shows the text and the diagram side by side
SIDE_BY_SIDE = 100
#: the diagram pane's width beside the text
DIAGRAM_WIDTH = 40
SAVE_HELP = (
    "The file is written whole (a crash leaves the old file or the new one). An FSM file's "
    "name ends in .yaml."
)
HIGHLIGHT_STATE = "bold reverse"
HIGHLIGHT_ARROW = "bold underline"


def _problem_text(checked: Checked) -> str:
    if checked.definition is not None:
        d = checked.definition
        count = len(d.states)
        states = "1 state" if count == 1 else f"{count} states"
        return f"No problems: {states}. ctrl+r saves and runs it."
    lines = []
    for p in checked.problems:
        where = f"{p.line}:{p.column} " if p.line else ""
        lines.append(f"{where}{p.message}" + (f" (hint: {p.hint})" if p.hint else ""))
    return "\n".join(lines)


class FsmEditorScreen(ShowsSnapshot, FollowsUnicode, SingleLayout, Screen[None]):
    """Write, check, save and run an FSM file."""

    DEFAULT_CSS = """
    FsmEditorScreen #fsm-title {
        height: 1;
        padding: 0 1;
        background: $boost;
        text-style: bold;
    }
    FsmEditorScreen #fsm-body {
        height: 1fr;
    }
    FsmEditorScreen #fsm-text {
        width: 1fr;
        height: 1fr;
        border: none;
        padding: 0;
    }
    FsmEditorScreen #fsm-diagram-box {
        width: 40;
        height: 1fr;
        border-left: vkey $panel;
        scrollbar-size-vertical: 1;
    }
    FsmEditorScreen.-narrow #fsm-diagram-box {
        width: 1fr;
        border-left: none;
        display: none;
    }
    FsmEditorScreen.-narrow.-diagram #fsm-diagram-box {
        display: block;
    }
    FsmEditorScreen.-narrow.-diagram #fsm-text {
        display: none;
    }
    FsmEditorScreen #fsm-problems-box {
        height: auto;
        max-height: 4;
        scrollbar-size-vertical: 1;
        border-top: solid $panel;
    }
    FsmEditorScreen #fsm-problems {
        color: $text-error;
    }
    FsmEditorScreen #fsm-problems.-ok {
        color: $text-success;
    }
    FsmEditorScreen #fsm-status {
        height: 1;
        color: $text-muted;
    }
    FsmEditorScreen #fsm-status.-error {
        color: $text-error;
    }
    """

    BINDINGS: ClassVar[list[BindingType]] = [*bindings(*FSM_EDITOR_KEY_IDS)]

    def __init__(self, station: LabStation, path: str = "", unicode: bool = False) -> None:
        super().__init__()
        self.station = station
        self._unicode = unicode
        self._typed = path
        self.draft = FsmDraft(station.files)
        #: the text's last check, and how many checks have finished
        self.checked: Checked | None = None
        self.checks = 0
        #: the text that last check read
        self.checked_text: str | None = None
        self.diagram: Diagram | None = None
        #: the state and transition the diagram shows as current: (state, (state, index))
        self.lit: tuple[str | None, tuple[str, int] | None] = (None, None)
        self.status = ""
        self._timer: Timer | None = None
        self._checking = False
        self._opened_text = ""

    # -- layout ----------------------------------------------------------------------------
    def compose(self) -> ComposeResult:
        yield Static(id="fsm-title", markup=False)
        with Horizontal(id="fsm-body"):
            area = TextArea(id="fsm-text", show_line_numbers=True, tab_behavior="indent")
            yield area
            with VerticalScroll(id="fsm-diagram-box"):
                yield Static(id="fsm-diagram", markup=False)
        with VerticalScroll(id="fsm-problems-box", can_focus=False):
            yield Static(id="fsm-problems", markup=False)
        yield Static(id="fsm-status", markup=False)
        yield KeyBar()

    def on_mount(self) -> None:
        area = self.query_one(TextArea)
        if "yaml" in area.available_languages:
            area.language = "yaml"
        self._open(self._typed)
        area.focus()

    def _open(self, typed: str) -> None:
        station = self.station
        text = ""
        if typed:
            try:
                draft = FsmDraft.open(station.files, typed)
            except FsmEditError as exc:
                self._status(str(exc), error=True)
                draft = FsmDraft(station.files)
            else:
                text = draft.saved
                if not station.files.allows_writing(draft.path):
                    # a built-in or a starter: its text to start from, saved under a new name
                    name = Path(draft.path).name
                    self._status(f"{name} comes with the workbench: ctrl+s saves your own copy")
                    draft = FsmDraft(station.files)
            self.draft = draft
        if not text:
            text = new_text("my-fsm", station.sensors, station.profile)
            self._status("a new machine: add states (ctrl+n) and transitions (ctrl+b), or type")
        self._opened_text = text
        area = self.query_one(TextArea)
        area.load_text(text)
        self._title()
        self._check_soon(0)

    # -- public ------------------------------------------------------------------------------
    @property
    def text(self) -> str:
        return self.query_one(TextArea).text

    @property
    def dirty(self) -> bool:
        return self.text != (self.draft.saved if self.draft.path else self._opened_text)

    def set_unicode(self, unicode: bool) -> None:
        self._unicode = unicode
        if self.is_mounted:
            self._draw_diagram()

    # -- checking ----------------------------------------------------------------------------
    @on(TextArea.Changed, "#fsm-text")
    def _changed(self, event: TextArea.Changed) -> None:
        self._title()
        self._check_soon(CHECK_DELAY)

    def _check_soon(self, delay: float) -> None:
        if self._timer is not None:
            self._timer.stop()
        self._timer = self.set_timer(delay, self._start_check) if delay else None
        if not delay:
            self._start_check()

    def _start_check(self) -> None:
        if self._checking:
            return  # one check at a time: the one under way looks again when it is done
        self._checking = True
        self.run_worker(self._check(self.text), group="fsm-check")

    async def _check(self, text: str) -> None:
        name = self.draft.shown if self.draft.path else "my-fsm.yaml"
        try:
            checked = await asyncio.to_thread(check, text, name)
        finally:
            self._checking = False
        if text != self.text:
            self._start_check()  # typed on meanwhile: check the text as it is now
            return
        self.checked = checked
        self.checked_text = text
        self.checks += 1
        problems = self.query_one("#fsm-problems", Static)
        problems.update(_problem_text(checked))
        problems.set_class(checked.definition is not None, "-ok")
        if checked.definition is not None:
            self.diagram = None  # drawn again for the new machine
        self._draw_diagram()

    # -- the diagram -------------------------------------------------------------------------
    def _draw_diagram(self) -> None:
        checked = self.checked
        widget = self.query_one("#fsm-diagram", Static)
        if checked is None or checked.definition is None:
            if self.diagram is None:
                widget.update("The diagram shows once the file has no problems.")
            return
        definition = checked.definition
        box = self.query_one("#fsm-diagram-box")
        if box.display and not box.size.width:
            self.call_after_refresh(self._draw_diagram)  # not laid out yet: once it is
            return
        width = max(20, (box.size.width or DIAGRAM_WIDTH) - 2)
        self.diagram = layout(definition, width, self._unicode, state_notes(definition))
        self._light()

    def _light(self) -> None:
        diagram = self.diagram
        if diagram is None:
            return
        state, arrow = self.lit
        marked: dict[int, str] = {}
        if state is not None and state in diagram.boxes:
            first, last = diagram.boxes[state]
            marked.update({i: HIGHLIGHT_STATE for i in range(first, last + 1)})
        if arrow is not None and arrow in diagram.arrows:
            first, last = diagram.arrows[arrow]
            marked.update({i: HIGHLIGHT_ARROW for i in range(first, last + 1)})
        text = Text()
        for i, line in enumerate(diagram.lines):
            text.append(line, style=marked.get(i, ""))
            text.append("\n")
        self.query_one("#fsm-diagram", Static).update(text)

    def show_snapshot(self, snapshot: Snapshot) -> None:
        """While this file's machine drives, light its current state and last transition."""
        if not self.is_mounted:
            return
        lit = self._live()
        if lit != self.lit:
            self.lit = lit
            self._light()

    def _live(self) -> tuple[str | None, tuple[str, int] | None]:
        station = self.station
        driving = station.driving
        controller = driving.controller if driving is not None else None
        if not isinstance(controller, FsmController) or not self.draft.path:
            return (None, None)
        if controller.definition.source != self.draft.path:
            return (None, None)
        arrow = None
        if controller.history:
            last = controller.history[-1]
            try:
                source = controller.definition.state(last.source)
            except KeyError:
                source = None
            if source is not None:
                for j, tr in enumerate(source.transitions):
                    if tr.target == last.target and tr.when == last.guard_text:
                        arrow = (last.source, j)
                        break
        return (controller.state, arrow)

    def on_resize(self, event: Resize) -> None:
        self.set_class(event.size.width < SIDE_BY_SIDE, "-narrow")
        self.call_after_refresh(self._draw_diagram)  # laid out again for the new width

    def action_toggle_diagram(self) -> None:
        showing = not self.has_class("-diagram")
        self.set_class(showing, "-diagram")
        if not self.has_class("-narrow"):
            self._status("the diagram is beside the text: ctrl+t matters below 100 columns")
            return
        if showing:
            self.call_after_refresh(self._draw_diagram)
            self.query_one("#fsm-diagram-box").focus()
        else:
            self.query_one(TextArea).focus()

    # -- status ------------------------------------------------------------------------------
    def _title(self) -> None:
        marker = " (modified)" if self.dirty else ""
        self.query_one("#fsm-title", Static).update(f"FSM editor{marker}  [{self.draft.shown}]")

    def _status(self, text: str, error: bool = False) -> None:
        self.status = text
        if self.is_mounted:
            status = self.query_one("#fsm-status", Static)
            status.update(text)
            status.set_class(error, "-error")

    # -- forms ---------------------------------------------------------------------------------
    def action_add_state(self) -> None:
        self._form("state")

    def action_add_transition(self) -> None:
        self._form("transition")

    def _form(self, kind: str) -> None:
        def done(edited: Edited | None) -> None:
            if edited is None:
                return
            area = self.query_one(TextArea)
            # one edit replacing the whole text: ctrl+z takes it back as a whole
            area.replace(edited.text, (0, 0), area.document.end)
            area.cursor_location = (edited.line, 0)
            area.scroll_cursor_visible()
            area.focus()
            self._status(f"added: line {edited.line + 1}; ctrl+z takes it back")

        self.app.push_screen(FormDialog(FORMS[kind], self.text), done)

    # -- saving and running -------------------------------------------------------------------
    def _save(self, typed: str | None) -> bool:
        try:
            written = self.draft.save(self.text, typed)
        except FsmEditError as exc:
            self._status(str(exc), error=True)
            return False
        problems = self.checked is not None and self.checked.definition is None
        extra = " (with problems still to fix)" if problems else ""
        self._status(f"saved to {self.station.files.shown(written)}{extra}")
        self._title()
        return True

    def action_save(self) -> None:
        if self.draft.path:
            self._save(None)
        else:
            self._ask_path(None)

    def _ask_path(
        self, after: Callable[[], object] | None, value: str | None = None, error: str = ""
    ) -> None:
        def chosen(path: str | None) -> None:
            if path is None:
                return
            if self._save(path):
                if after is not None:
                    after()
            else:
                self._ask_path(after, path, self.status)

        self.app.push_screen(
            PathDialog(
                "Save FSM as",
                SAVE_HELP,
                value=self.draft.suggested() if value is None else value,
                note=self.station.files.note(),
                action="Save",
                error=error,
            ),
            chosen,
        )

    def action_run(self) -> None:
        """Save (asking where the first time), choose the file on the station and start it."""
        if not self.draft.path:
            self._ask_path(self._run)
        elif self.dirty:
            if self._save(None):
                self._run()
        else:
            self._run()

    def _run(self) -> None:
        station = self.station
        try:
            definition = station.select_algorithm(self.draft.path)
        except FsmFileError as exc:
            count = len(exc.problems)
            self._status(f"not run: {count} problem{'s' * (count != 1)} to fix first", True)
            return
        except (FsmError, OSError, OutsideWorkspace) as exc:
            self._status(f"not run: {exc}", error=True)
            return
        fitted = ""
        if station.missing_sensors():
            station.apply_algorithm_preset()
            fitted = f"; sensors set for it: {', '.join(str(s) for s in station.sensors)}"
        try:
            station.start()
        except (FsmError, ValueError) as exc:
            self._status(f"not run: {exc}", error=True)
            return
        self.post_message(StationChanged())
        self._status(f"{definition.name} runs{fitted}: the diagram lights its state")

    # -- leaving -------------------------------------------------------------------------------
    def ask_before(self, action: Callable[[], object]) -> None:
        """Run ``action`` once the changes are saved or discarded (at once when none)."""
        if not self.dirty:
            action()
            return

        def chosen(choice: Choice | None) -> None:
            if choice == "save":
                if self.draft.path:
                    if self._save(None):
                        action()
                else:
                    self._ask_path(action)
            elif choice == "discard":
                action()

        title = f"The FSM {self.draft.shown}" if self.draft.path else "This new FSM"
        self.app.push_screen(UnsavedDialog(title), chosen)

    def action_leave(self) -> None:
        self.ask_before(self._leave)

    def _leave(self) -> None:
        if self.app.screen is self:
            self.dismiss(None)
