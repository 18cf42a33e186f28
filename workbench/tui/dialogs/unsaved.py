"""Asks what to do with unsaved maze changes: save, discard or cancel."""

from __future__ import annotations

from typing import ClassVar, Literal

from textual import on
from textual.app import ComposeResult
from textual.binding import BindingType
from textual.containers import Horizontal, Vertical
from textual.widgets import Button, Static

from ..keys import bindings
from .frame import Dialog

Choice = Literal["save", "discard", "cancel"]


class UnsavedDialog(Dialog[Choice | None]):
    """Dismisses with "save", "discard" or "cancel" (escape cancels too)."""

    BINDINGS: ClassVar[list[BindingType]] = [*bindings(
        "unsaved.save", "unsaved.discard", "unsaved.cancel"
    )]

    def __init__(self, title: str, detail: str = "") -> None:
        super().__init__()
        self._title = title
        self._detail = detail

    def compose(self) -> ComposeResult:
        with Vertical(id="dialog") as box:
            box.border_title = "Unsaved changes"
            yield Static(f"{self._title} has changes that are not saved.", classes="help")
            if self._detail:
                yield Static(self._detail, classes="help")
            with Horizontal(id="buttons"):
                yield Button("Save (s)", id="save", variant="primary", compact=True)
                yield Button("Discard (d)", id="discard", variant="error", compact=True)
                yield Button("Cancel (c)", id="cancel", compact=True)

    def on_mount(self) -> None:
        self.query_one("#save", Button).focus()

    def action_choose(self, choice: Choice) -> None:
        self.dismiss(choice)

    def action_cancel(self) -> None:
        self.dismiss("cancel")

    @on(Button.Pressed, "#save")
    def _save(self, event: Button.Pressed) -> None:
        event.stop()
        self.dismiss("save")

    @on(Button.Pressed, "#discard")
    def _discard(self, event: Button.Pressed) -> None:
        event.stop()
        self.dismiss("discard")
