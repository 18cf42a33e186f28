"""One row of the sensor port panel: kind, port number and mount, the live reading, and the
row's problem shown right under it."""

from __future__ import annotations

from textual.app import ComposeResult
from textual.containers import Horizontal, Vertical
from textual.message import Message
from textual.widgets import Button, Input, Label, Select, Static

from workbench.control.bench import SensorRow
from workbench.sim.sensors import KINDS

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
        self._row = row

    def compose(self) -> ComposeResult:
        row = self._row
        with Horizontal():
            yield Label(f"{self.number}.", classes="row-number")
            yield Select(
                [(k, k) for k in KINDS],
                value=row.kind,
                allow_blank=False,
                compact=True,
                classes="row-kind",
            )
            yield Input(row.port, compact=True, max_length=4, classes="row-port")
            yield Select(
                [(m, m) for m in MOUNT_CHOICES],
                value=row.mount or "none",
                allow_blank=False,
                compact=True,
                classes="row-mount",
            )
            yield Label("", classes="row-reading", markup=False)
            yield Button("x", compact=True, classes="row-remove", tooltip="remove this row")
        yield Static("", classes="row-error", markup=False)

    def row(self) -> SensorRow:
        kind = self.query_one(".row-kind", Select).value
        mount = self.query_one(".row-mount", Select).value
        port = self.query_one(".row-port", Input).value
        return SensorRow(str(kind), port, None if mount == "none" else str(mount))

    def set_number(self, number: int) -> None:
        self.number = number
        self.query_one(".row-number", Label).update(f"{number}.")

    def set_error(self, error: str | None) -> None:
        self.query_one(".row-error", Static).update(error or "")
        self.set_class(bool(error), "-invalid")

    @property
    def error(self) -> str | None:
        return str(self.query_one(".row-error", Static).content) or None

    def set_reading(self, text: str) -> None:
        label = self.query_one(".row-reading", Label)
        if str(label.content) != text:
            label.update(text)

    def on_button_pressed(self, event: Button.Pressed) -> None:
        event.stop()
        self.post_message(self.Removed(self))
