"""The FSM editor's forms: add a state, add a transition. A form dismisses with the edited
text (the edit itself is :mod:`workbench.fsm.forms`'), or None when cancelled; an
entry that cannot be written keeps the dialog open with the reason."""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass

from textual import on
from textual.app import ComposeResult
from textual.containers import Horizontal, Vertical
from textual.widgets import Button, Input, Label, Static

from workbench.fsm.forms import Edited, FormError, add_state, add_transition

from ..widgets.field import Field
from .frame import Dialog


@dataclass(frozen=True)
class Form:
    """One form: its title, its help, its fields (id, label, placeholder) and the edit it
    makes of the text with the values typed."""

    title: str
    help: str
    fields: tuple[tuple[str, str, str], ...]
    edit: Callable[[str, Mapping[str, str]], Edited]


STATE = Form(
    "Add a state",
    "A state and what the robot does on entering it. Actions, separated by ';': "
    "move: 1 | turn: -90 | wheels: 0.5, 0.5 | stop | timer: 2 | set: turns = turns + 1",
    (("state-name", "Name", "e.g. Forward"), ("state-actions", "Actions", "e.g. move: 1")),
    lambda text, v: add_state(text, v["state-name"], v["state-actions"]),
)
TRANSITION = Form(
    "Add a transition",
    "When the condition holds in the 'from' state, the machine goes to the 'to' state (the "
    "first true one of a state wins; empty: at the next tick). Set: assignments made on the "
    "way, e.g. turns = turns + 1.",
    (
        ("tr-from", "From", "a state"),
        ("tr-to", "To", "a state"),
        ("tr-when", "When", "e.g. front < 50"),
        ("tr-set", "Set", "e.g. turns = turns + 1"),
    ),
    lambda text, v: add_transition(text, v["tr-from"], v["tr-to"], v["tr-when"], v["tr-set"]),
)
#: the FSM editor's forms by name
FORMS = {"state": STATE, "transition": TRANSITION}


class FormDialog(Dialog[Edited | None]):
    """A form of labelled fields over the FSM text; Add makes its edit, which may refuse."""

    def __init__(self, form: Form, text: str) -> None:
        super().__init__()
        self.form = form
        self._text = text

    def compose(self) -> ComposeResult:
        with Vertical(id="dialog") as box:
            box.border_title = self.form.title
            yield Static(self.form.help, classes="help", markup=False)
            for field_id, label, placeholder in self.form.fields:
                with Horizontal(classes="field"):
                    yield Label(label)
                    yield Field(placeholder=placeholder, id=field_id, compact=True)
            yield Static("", id="error", classes="-empty", markup=False)
            with Horizontal(id="buttons"):
                yield Button("Add", id="ok", variant="primary", compact=True)
                yield Button("Cancel", id="cancel", compact=True)

    def on_mount(self) -> None:
        self.query_one(f"#{self.form.fields[0][0]}", Input).focus()

    @on(Input.Submitted)
    @on(Button.Pressed, "#ok")
    def submit(self, event: Input.Submitted | Button.Pressed) -> None:
        event.stop()
        values = {f[0]: self.query_one(f"#{f[0]}", Input).value for f in self.form.fields}
        try:
            edited = self.form.edit(self._text, values)
        except FormError as exc:
            self.show_error(str(exc))
            return
        self.dismiss(edited)
