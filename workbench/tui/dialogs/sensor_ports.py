"""The sensor port panel, modelled on the Web Simulator's: which sensor sits on which port.

Rows of kind / port / mount; "Apply" puts them on the live robot, or, when a row is wrong (a
port used twice, a number out of range), marks that row and changes nothing. Presets set the
course simulators' configurations at once. Each row shows the live reading of its port.
"""

from __future__ import annotations

from typing import ClassVar

from textual import on
from textual.app import ComposeResult
from textual.binding import BindingType
from textual.containers import Horizontal, Vertical, VerticalScroll
from textual.screen import ModalScreen
from textual.widgets import Button, Input, Label, Select, Static

from workbench.control.station import PRESETS, LabStation, SensorRow, check_sensor_rows
from workbench.sim.profiles import get_profile
from workbench.sim.sensor_kinds import SENSOR_KINDS
from workbench.sim.sensors import PORT_RANGE
from workbench.sim.session import Snapshot

from ..host import Say, ShowsSnapshot, StationChanged
from ..keys import bindings
from ..widgets.sensor_row_editor import SensorRowEditor
from ..widgets.text import reading

PRESET_LABELS = {
    "unity": "Unity",
    "web-wall-following": "Web wall-following",
    "web-two-distance": "Web two-distance",
}
MAX_ROWS = 8


class SensorPortsModal(ShowsSnapshot, ModalScreen[None]):
    """Edit the robot's sensors; the live robot changes only on Apply or a preset."""

    DEFAULT_CSS = """
    SensorPortsModal {
        align: center middle;
    }
    SensorPortsModal > #ports-dialog {
        width: 78;
        height: auto;
        max-height: 100%;
        border: round $primary;
        border-title-color: $text-primary;
        border-subtitle-color: $text-muted;
        background: $surface;
        padding: 0 1;
    }
    SensorPortsModal #ports-head {
        height: 1;
        color: $text-muted;
        text-style: bold;
    }
    SensorPortsModal #ports-rows {
        height: auto;
        max-height: 12;
    }
    SensorPortsModal .button-row {
        height: 1;
        margin-top: 1;
    }
    SensorPortsModal .button-row Button {
        margin-right: 2;
        min-width: 0;
        width: auto;
    }
    SensorPortsModal .button-row Label {
        margin-right: 1;
        color: $text-muted;
    }
    SensorPortsModal .spacer {
        width: 1fr;
    }
    SensorPortsModal #ports-status {
        height: auto;
        color: $text-warning;
    }
    """

    BINDINGS: ClassVar[list[BindingType]] = [*bindings("dialog.close", "sensors.add")]

    def __init__(self, station: LabStation) -> None:
        super().__init__()
        self.station = station
        self._ready = False

    def compose(self) -> ComposeResult:
        dialog = Vertical(id="ports-dialog")
        dialog.border_title = f"Sensor ports ({self.station.profile})"
        dialog.border_subtitle = "enter or Apply puts them on the robot, escape closes"
        with dialog:
            yield Label("#   kind          port   mount         live reading", id="ports-head")
            with VerticalScroll(id="ports-rows"):
                for i, row in enumerate(self.station.sensor_rows()):
                    yield SensorRowEditor(i + 1, row)
            with Horizontal(classes="button-row", id="ports-presets"):
                yield Label("Presets:")
                for name in PRESETS:
                    yield Button(PRESET_LABELS.get(name, name), id=f"preset-{name}", compact=True)
            with Horizontal(classes="button-row"):
                yield Button("Add row", id="ports-add", compact=True)
                yield Static(classes="spacer")
                yield Button("Apply", id="ports-apply", variant="primary", compact=True)
                yield Button("Close", id="ports-close", compact=True)
            yield Static("", id="ports-status", markup=False)

    def on_mount(self) -> None:
        self._ready = True
        self.show_snapshot(self.station.snapshot())
        self.query(SensorRowEditor).first().query_one(".row-port", Input).focus()

    # -- reading ---------------------------------------------------------------------------
    @property
    def editors(self) -> list[SensorRowEditor]:
        return list(self.query(SensorRowEditor))

    def rows(self) -> list[SensorRow]:
        return [editor.row() for editor in self.editors]

    def show_snapshot(self, snapshot: Snapshot) -> None:
        """The live reading of each row's port (when the robot has that sensor there)."""
        if not self._ready:
            return  # the app ticks while the dialog is still being built
        profile = get_profile(self.station.profile)
        live = {spec.port: spec for spec in snapshot.sensors}
        for editor in self.editors:
            row = editor.row()
            spec = live.get(int(row.port)) if row.port.strip().isdigit() else None
            if row.mount is None:
                text = "not mounted"
            elif spec is None or (spec.kind, spec.mount) != (row.kind, row.mount):
                text = "not applied yet"
            else:
                value = snapshot.readings.get(spec.port)
                text = reading(spec, value, profile.unit, profile.no_echo)
            editor.set_reading(text)

    def _status(self, text: str) -> None:
        self.query_one("#ports-status", Static).update(text)

    # -- actions -----------------------------------------------------------------------------
    def action_apply(self) -> None:
        editors = self.editors
        errors = self.station.apply_sensor_rows([e.row() for e in editors])
        for i, editor in enumerate(editors):
            editor.set_error(errors.get(i))
        if errors:
            count = len(errors)
            self._status(
                f"nothing applied: {count} row{'s' if count > 1 else ''} to fix (marked above)"
            )
        else:
            specs = ", ".join(str(s) for s in self.station.sensors) or "no sensors"
            self._status(f"applied: {specs}")
            self.post_message(Say(""))
        self._refresh_all()

    async def action_add_row(self) -> None:
        editors = self.editors
        if len(editors) >= MAX_ROWS:
            self._status(f"at most {MAX_ROWS} sensor rows")
            return
        used = {r.port.strip() for r in self.rows()}
        port = next((str(p) for p in PORT_RANGE if p > 0 and str(p) not in used), "")
        editor = SensorRowEditor(len(editors) + 1, SensorRow(SENSOR_KINDS[0].name, port, None))
        await self.query_one("#ports-rows").mount(editor)
        editor.scroll_visible()
        editor.query_one(".row-port", Input).focus()
        self.show_snapshot(self.station.snapshot())

    async def apply_preset(self, name: str) -> None:
        self.station.apply_preset(name)
        await self._rebuild_rows()
        specs = ", ".join(str(s) for s in self.station.sensors)
        self._status(f"preset {PRESET_LABELS.get(name, name)} applied: {specs}")
        self._refresh_all()

    async def _rebuild_rows(self) -> None:
        container = self.query_one("#ports-rows")
        await container.remove_children()
        await container.mount_all(
            SensorRowEditor(i + 1, row) for i, row in enumerate(self.station.sensor_rows())
        )

    def _refresh_all(self) -> None:
        self.show_snapshot(self.station.snapshot())
        self.post_message(StationChanged())

    def action_close(self) -> None:
        self.dismiss()

    # -- events ------------------------------------------------------------------------------
    @on(Button.Pressed, "#ports-apply")
    def _apply_pressed(self) -> None:
        self.action_apply()

    @on(Button.Pressed, "#ports-close")
    def _close_pressed(self) -> None:
        self.dismiss()

    @on(Button.Pressed, "#ports-add")
    async def _add_pressed(self) -> None:
        await self.action_add_row()

    @on(Button.Pressed, "#ports-presets Button")
    async def _preset_pressed(self, event: Button.Pressed) -> None:
        assert event.button.id is not None
        await self.apply_preset(event.button.id.removeprefix("preset-"))

    @on(Input.Submitted)
    def _port_submitted(self) -> None:
        self.action_apply()

    @on(Input.Changed)
    @on(Select.Changed)
    def _row_changed(self) -> None:
        """Check the rows as they are typed; the robot changes only on Apply."""
        editors = self.editors
        _, errors = check_sensor_rows([e.row() for e in editors])
        for i, editor in enumerate(editors):
            editor.set_error(errors.get(i))
        self.show_snapshot(self.station.snapshot())

    async def on_sensor_row_editor_removed(self, event: SensorRowEditor.Removed) -> None:
        await event.editor.remove()
        for i, editor in enumerate(self.editors):
            editor.set_number(i + 1)
        self._row_changed()
        self._status("row removed: Apply to take it off the robot")
