"""The "who is at this robot" dialog shown when the workbench starts.

The student's name (prefilled with the login or SSH user name) and an optional lab partner;
the labs keep progress and sign-offs under the student's name. When the name comes from the
SSH login it cannot be changed here, only the partner.
"""

from __future__ import annotations

from textual import on
from textual.app import ComposeResult
from textual.containers import Horizontal, Vertical
from textual.widgets import Button, Input, Label, Static

from workbench.labs.names import MAX_STUDENT_NAME, NameProblem, check_pair

from ..widgets.field import Field
from .frame import Dialog


class IdentityDialog(Dialog[tuple[str, str] | None]):
    """Asks for the student and the partner; dismisses with (student, partner).

    Escape keeps the names shown when the dialog opened (the defaults).
    """

    def __init__(self, student: str, partner: str = "", student_fixed: bool = False) -> None:
        super().__init__()
        self._student = student
        self._partner = partner
        self._fixed = student_fixed

    def compose(self) -> ComposeResult:
        with Vertical(id="dialog") as box:
            box.border_title = "Who is at this robot?"
            yield Static(
                "Lab progress and sign-offs are kept under the student's name. "
                "Working in a pair? Add your partner; the labs ask you to swap the driver "
                "after each sign-off.",
                classes="help",
            )
            with Horizontal(classes="field"):
                yield Label("Student")
                yield Field(
                    self._student,
                    id="student",
                    compact=True,
                    disabled=self._fixed,
                    max_length=MAX_STUDENT_NAME,
                )
            with Horizontal(classes="field"):
                yield Label("Partner")
                yield Field(
                    self._partner,
                    id="partner",
                    compact=True,
                    placeholder="optional",
                    max_length=MAX_STUDENT_NAME,
                )
            yield Static("", id="error", classes="-empty")
            with Horizontal(id="buttons"):
                yield Button("Start", id="ok", variant="primary", compact=True)

    def show_student(self, student: str) -> None:
        """The student at the robot is ``student`` (a spare app given its session; before the
        dialog has its fields, they are made with it)."""
        self._student = student
        for field in self.query("#student").results(Input):
            field.value = student

    def on_mount(self) -> None:
        self.query_one("#partner" if self._fixed else "#student", Input).focus()

    def action_cancel(self) -> None:
        self.dismiss((self._student, self._partner))

    @on(Field.Capped)
    def _name_too_long(self, event: Field.Capped) -> None:
        self.show_error(f"a name is at most {event.limit} characters: the rest was not kept")

    @on(Input.Submitted)
    @on(Button.Pressed, "#ok")
    def submit(self, event: Input.Submitted | Button.Pressed) -> None:
        event.stop()
        student = self._student if self._fixed else self.query_one("#student", Input).value
        partner = self.query_one("#partner", Input).value
        try:
            pair = check_pair(student, partner)
        except NameProblem as exc:
            self.show_error(str(exc))
            return
        self.dismiss(pair)
