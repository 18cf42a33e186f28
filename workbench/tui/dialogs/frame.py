"""The frame shared by the small dialogs: a titled box in the middle, an error line, buttons."""

from __future__ import annotations

from typing import ClassVar, TypeVar

from textual import on
from textual.binding import BindingType
from textual.screen import ModalScreen
from textual.widgets import Button, Static

from ..keys import bindings

ResultType = TypeVar("ResultType")


class Dialog(ModalScreen[ResultType]):
    """A modal box; escape or Cancel dismisses it with None."""

    DEFAULT_CSS = """
    Dialog {
        align: center middle;
        background: $background 60%;
    }
    Dialog > #dialog {
        width: 56;
        max-width: 100%;
        height: auto;
        max-height: 100%;
        border: round $primary;
        border-title-color: $text-primary;
        border-title-style: bold;
        background: $surface;
        padding: 0 1;
    }
    Dialog .field {
        height: 1;
        margin-top: 1;
    }
    Dialog .field > Label {
        width: 9;
    }
    Dialog .field > Input, Dialog .field > Select {
        width: 1fr;
    }
    Dialog .help {
        color: $text-muted;
        margin-top: 1;
    }
    Dialog #error {
        color: $text-error;
        margin-top: 1;
        height: auto;
    }
    Dialog #error.-empty {
        display: none;
    }
    /* many problems (a maze file full of them) scroll, so the buttons stay on the screen */
    Dialog #error-box {
        height: auto;
        max-height: 9;
        scrollbar-size-vertical: 1;
    }
    Dialog #buttons {
        height: 1;
        margin-top: 1;
        align-horizontal: right;
    }
    Dialog #buttons > Button {
        margin-left: 2;
    }
    """

    BINDINGS: ClassVar[list[BindingType]] = [*bindings("dialog.cancel")]

    def show_error(self, text: str) -> None:
        """Show why the input cannot be used (empty text hides the line)."""
        error = self.query_one("#error", Static)
        error.update(text)
        error.set_class(not text, "-empty")

    def action_cancel(self) -> None:
        self.dismiss(None)

    @on(Button.Pressed, "#cancel")
    def _cancel_pressed(self, event: Button.Pressed) -> None:
        event.stop()
        self.action_cancel()
