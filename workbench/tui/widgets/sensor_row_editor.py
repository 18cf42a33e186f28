"""One row of the sensor port panel: kind, port number and mount, the live reading, and the
row's problem shown right under it."""

from __future__ import annotations

from textual.app import ComposeResult
from textual.containers import Horizontal, Vertical
from textual.message import Message
from textual.widgets import Button, Label, Select, Static

from workbench.control.station import SensorRow
from workbench.sim.sensor_kinds import SENSOR_KINDS

from ..plain import follow_app
from .field import Field

MOUNT_CHOICES = ("front", "left", "right", "back", "none")


class SensorRowEditor(Vertical):
    """Edits one :class:`SensorRow`; posts :class:`SensorRowEditor.Removed` for its x button."""

    DEFAULT_CSS = """
    SensorRowEditor {
        height: auto;
    }
    SensorRowEditor > Horizontal {
        height: 1;
    }
    SensorRowEditor .row-number {
        width: 4;
        color: $text-muted;
    }
    SensorRowEditor Select {
        width: 13;
        margin-right: 1;
    }
    SensorRowEditor Input {
        width: 6;
        margin-right: 1;
        background: $panel;
    }
    SensorRowEditor .row-reading {
        width: 1fr;
        color: $text-success;
    }
    SensorRowEditor .row-remove {
        min-width: 3;
        width: 3;
    }
    SensorRowEditor .row-error {
        height: auto;
        padding-left: 4;
        color: $text-error;
        display: none;
    }
    SensorRowEditor.-invalid .row-error {
        display: block;
    }
    SensorRowEditor.-invalid Input {
        background: $error 30%;
    }
    """

    class Removed(Message):
        def __init__(self, editor: SensorRowEditor) -> None:
            super().__init__()
            self.editor = editor

    def __init__(self, number: int, row: SensorRow) -> None:
        super().__init__()
        self.number = number
        self._number = Label(f"{number}.", classes="row-number")
        self._kind = Select(
            [(k.panel.label, k.name) for k in SENSOR_KINDS],
            value=row.kind,
            allow_blank=False,
            compact=True,
            classes="row-kind",
        )
        self._port = Field(row.port, compact=True, max_length=4, classes="row-port")
        self._mount = Select(
            [(m, m) for m in MOUNT_CHOICES],
            value=row.mount or "none",
            allow_blank=False,
            compact=True,
            classes="row-mount",
        )
        self._reading = Label("", classes="row-reading", markup=False)
        self._error = Static("", classes="row-error", markup=False)
        self._error_text: str | None = None

    def compose(self) -> ComposeResult:
        with Horizontal():
            yield self._number
            yield self._kind
            yield self._port
            yield self._mount
            yield self._reading
            yield Button("x", compact=True, classes="row-remove", tooltip="remove this row")
        yield self._error

    def on_mount(self) -> None:
        follow_app(self)

    def row(self) -> SensorRow:
        mount = self._mount.value
        return SensorRow(
            str(self._kind.value), self._port.value, None if mount == "none" else str(mount)
        )

    def set_number(self, number: int) -> None:
        self.number = number
        self._number.update(f"{number}.")

    def set_error(self, error: str | None) -> None:
        if error == self._error_text:
            return
        self._error_text = error
        self._error.update(error or "")
        self.set_class(bool(error), "-invalid")

    @property
    def error(self) -> str | None:
        return self._error_text

    def set_reading(self, text: str) -> None:
        if str(self._reading.content) != text:
            self._reading.update(text)

    def on_button_pressed(self, event: Button.Pressed) -> None:
        event.stop()
        self.post_message(self.Removed(self))
