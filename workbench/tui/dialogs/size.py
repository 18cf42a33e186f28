"""The "new maze" dialog: a width and a height in blocks, checked before it closes."""

from __future__ import annotations

from textual import on
from textual.app import ComposeResult
from textual.containers import Horizontal, Vertical
from textual.widgets import Button, Input, Label, Static

from workbench.sim.editing import MIN_BLOCKS, EditorError, parse_size
from workbench.sim.maze import MAX_SIZE

from ..widgets.field import Field
from .frame import Dialog


class SizeDialog(Dialog[tuple[int, int] | None]):
    """Asks for a maze size in blocks; dismisses with (width, height) or None."""

    def __init__(self, width: int, height: int) -> None:
        super().__init__()
        self._width = width
        self._height = height

    def compose(self) -> ComposeResult:
        with Vertical(id="dialog") as box:
            box.border_title = "New maze"
            yield Static(
                f"An empty room of floor inside a closed wall, the start at (1, 1). "
                f"Sizes are in blocks, walls included ({MIN_BLOCKS}-{MAX_SIZE}).",
                classes="help",
            )
            with Horizontal(classes="field"):
                yield Label("Width")
                yield Field(str(self._width), id="width", compact=True, restrict=r"\d*")
            with Horizontal(classes="field"):
                yield Label("Height")
                yield Field(str(self._height), id="height", compact=True, restrict=r"\d*")
            yield Static("", id="error", classes="-empty")
            with Horizontal(id="buttons"):
                yield Button("Create", id="ok", variant="primary", compact=True)
                yield Button("Cancel", id="cancel", compact=True)

    def on_mount(self) -> None:
        self.query_one("#width", Input).focus()

    @on(Input.Submitted)
    @on(Button.Pressed, "#ok")
    def submit(self, event: Input.Submitted | Button.Pressed) -> None:
        event.stop()
        width = self.query_one("#width", Input).value
        height = self.query_one("#height", Input).value
        try:
            size = parse_size(width, height, MIN_BLOCKS, MAX_SIZE, "blocks")
        except EditorError as exc:
            self.show_error(str(exc))
            return
        self.dismiss(size)
