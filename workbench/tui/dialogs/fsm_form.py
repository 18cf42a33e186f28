"""The FSM editor's forms: add a state, add a transition. Each dismisses with the edited text
(the edit itself is :mod:`workbench.control.fsm_forms`'), or None when cancelled; an entry
that cannot be written keeps the dialog open with the reason."""

from __future__ import annotations

from collections.abc import Callable

from textual import on
from textual.app import ComposeResult
from textual.containers import Horizontal, Vertical
from textual.widgets import Button, Input, Label, Static

from workbench.control.fsm_forms import Edited, FormError, add_state, add_transition

from ..widgets.field import Field
from .frame import Dialog

STATE_HELP = (
    "A state and what the robot does on entering it. Actions, separated by ';': "
    "move: 1 | turn: -90 | wheels: 0.5, 0.5 | stop | timer: 2 | set: turns = turns + 1"
)
TRANSITION_HELP = (
    "When the condition holds in the 'from' state, the machine goes to the 'to' state (the "
    "first true one of a state wins; empty: at the next tick). Set: assignments made on the "
    "way, e.g. turns = turns + 1."
)


class _FormDialog(Dialog[Edited | None]):
    """A titled form of labelled fields; OK runs the edit, which may refuse."""

    TITLE_TEXT = ""
    HELP = ""
    #: (field id, label, placeholder)
    FIELDS: tuple[tuple[str, str, str], ...] = ()

    def __init__(self, text: str, values: dict[str, str] | None = None) -> None:
        super().__init__()
        self._text = text
        self._values = values or {}

    def compose(self) -> ComposeResult:
        with Vertical(id="dialog") as box:
            box.border_title = self.TITLE_TEXT
            yield Static(self.HELP, classes="help", markup=False)
            for field_id, label, placeholder in self.FIELDS:
                with Horizontal(classes="field"):
                    yield Label(label)
                    yield Field(
                        self._values.get(field_id, ""),
                        placeholder=placeholder,
                        id=field_id,
                        compact=True,
                    )
            yield Static("", id="error", classes="-empty", markup=False)
            with Horizontal(id="buttons"):
                yield Button("Add", id="ok", variant="primary", compact=True)
                yield Button("Cancel", id="cancel", compact=True)

    def on_mount(self) -> None:
        self.query_one(f"#{self.FIELDS[0][0]}", Input).focus()

    def value(self, field_id: str) -> str:
        return self.query_one(f"#{field_id}", Input).value

    def edit(self) -> Edited:
        raise NotImplementedError

    @on(Input.Submitted)
    @on(Button.Pressed, "#ok")
    def submit(self, event: Input.Submitted | Button.Pressed) -> None:
        event.stop()
        try:
            edited = self.edit()
        except FormError as exc:
            self.show_error(str(exc))
            return
        self.dismiss(edited)


class StateDialog(_FormDialog):
    TITLE_TEXT = "Add a state"
    HELP = STATE_HELP
    FIELDS = (
        ("state-name", "Name", "e.g. Forward"),
        ("state-actions", "Actions", "e.g. move: 1"),
    )

    def edit(self) -> Edited:
        return add_state(self._text, self.value("state-name"), self.value("state-actions"))


class TransitionDialog(_FormDialog):
    TITLE_TEXT = "Add a transition"
    HELP = TRANSITION_HELP
    FIELDS = (
        ("tr-from", "From", "a state"),
        ("tr-to", "To", "a state"),
        ("tr-when", "When", "e.g. front < 50"),
        ("tr-set", "Set", "e.g. turns = turns + 1"),
    )

    def edit(self) -> Edited:
        return add_transition(
            self._text,
            self.value("tr-from"),
            self.value("tr-to"),
            self.value("tr-when"),
            self.value("tr-set"),
        )


FORMS: dict[str, Callable[[str, dict[str, str]], _FormDialog]] = {
    "state": StateDialog,
    "transition": TransitionDialog,
}
