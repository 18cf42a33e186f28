"""A dialog asking for a file path (save as, open a run record)."""

from __future__ import annotations

from textual import on
from textual.app import ComposeResult
from textual.containers import Horizontal, Vertical, VerticalScroll
from textual.widgets import Button, Input, Label, Static

from ..widgets.field import Field
from .frame import Dialog


class PathDialog(Dialog[str | None]):
    """Asks for a path; dismisses with the path typed (stripped) or None.

    The caller does the work (saving, opening) and, when it fails, can open the dialog again
    with the same text and the reason in ``error``.
    """

    def __init__(
        self,
        title: str,
        help: str,
        value: str = "",
        action: str = "OK",
        error: str = "",
        note: str = "",
    ) -> None:
        super().__init__()
        self._note = note
        self._title = title
        self._help = help
        self._value = value
        self._action = action
        self._error = error

    def compose(self) -> ComposeResult:
        with Vertical(id="dialog") as box:
            box.border_title = self._title
            yield Static(self._help, classes="help")
            if self._note:
                yield Static(self._note, classes="help", id="note")
            with Horizontal(classes="field"):
                yield Label("Path")
                yield Field(self._value, id="path", compact=True)
            with VerticalScroll(id="error-box", can_focus=False):
                yield Static(self._error, id="error", classes="" if self._error else "-empty")
            with Horizontal(id="buttons"):
                yield Button(self._action, id="ok", variant="primary", compact=True)
                yield Button("Cancel", id="cancel", compact=True)

    def on_mount(self) -> None:
        self.query_one("#path", Input).focus()

    @on(Input.Submitted)
    @on(Button.Pressed, "#ok")
    def submit(self, event: Input.Submitted | Button.Pressed) -> None:
        event.stop()
        path = self.query_one("#path", Input).value.strip()
        if not path:
            self.show_error("type a path, e.g. mazes/my-maze.txt")
            return
        self.dismiss(path)
