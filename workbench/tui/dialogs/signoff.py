"""The instructor's sign-off of one exercise, at the student's terminal.

The instructor picks their name from the roster and types their passphrase; a note is optional
unless the sign-off overrides objectives that have not passed. Problems (a wrong passphrase, a
lock after too many, no roster) are shown in the dialog. After a sign-off the dialog asks who
drives next and records it; it returns that driver (None when closed without signing).
"""

from __future__ import annotations

import asyncio
from collections.abc import Callable
from typing import ClassVar

from textual import on
from textual.app import ComposeResult
from textual.binding import BindingType
from textual.containers import Horizontal, Vertical
from textual.screen import ModalScreen
from textual.widgets import Button, Input, Label, Static
from textual.worker import Worker

from workbench.labs.checks import ExerciseProgress
from workbench.labs.course_store import Store
from workbench.labs.progress import signoff_words
from workbench.labs.signoff.roster import roster_keys, roster_names
from workbench.labs.signoff.signing import sign_off
from workbench.labs.signoff.signoff_errors import SignoffError
from workbench.labs.signoff.signoff_record import Evidence, RecordFields, SignoffRecord

from ..keys import bindings
from ..plain import follow_app
from ..widgets.field import Field
from ..widgets.signoff_form import READING_ROSTER, SignoffForm


class SignoffModal(ModalScreen[str | None]):
    """Sign off an exercise; then choose who drives next."""

    DEFAULT_CSS = """
    SignoffModal {
        align: center middle;
    }
    SignoffModal > #signoff-dialog {
        width: 70;
        height: auto;
        max-height: 100%;
        border: round $primary;
        border-title-color: $text-primary;
        border-subtitle-color: $text-muted;
        background: $surface;
        padding: 0 1;
    }
    SignoffModal #signoff-sign-off, SignoffModal #signoff-next {
        height: auto;
    }
    SignoffModal #signoff-state {
        height: auto;
        color: $text-muted;
    }
    SignoffModal .button-row {
        height: 1;
        margin-top: 1;
    }
    SignoffModal .button-row Button {
        margin-right: 2;
        min-width: 0;
        width: auto;
    }
    SignoffModal .spacer {
        width: 1fr;
    }
    SignoffModal #signoff-status {
        height: auto;
        color: $text-warning;
    }
    SignoffModal #signoff-done {
        height: auto;
        color: $text-success;
    }
    """

    BINDINGS: ClassVar[list[BindingType]] = [*bindings("dialog.close")]

    def __init__(
        self,
        store: Store,
        progress: ExerciseProgress,
        student: str,
        partner: str = "",
        driver: str = "",
        already: str = "",
        on_signed: Callable[[SignoffRecord], None] | None = None,
    ) -> None:
        """``driver``: the person whose work the sign-off rests on. ``already`` says who
        signed the exercise off before, and when (empty when nobody has): the dialog is then
        a re-sign-off, which adds a second record. ``on_signed`` is told of the record the
        moment it is saved (before the dialog asks who drives next)."""
        super().__init__()
        self.on_signed = on_signed
        self.already = already
        self.store = store
        self.progress = progress
        self.student = student
        self.partner = partner
        self.driver = driver or student
        self.signed = False
        #: the sign-off under way (its key being unlocked), if any
        self.signing: Worker[None] | None = None
        #: escape was pressed while a sign-off was under way
        self.close_asked = False
        self.roster: list[str] = []
        self.roster_problem = ""
        #: set once the roster is read: at once from the data folder's files, in a thread
        #: from a course database (which may take its time, or not answer)
        self.roster_read = asyncio.Event()
        if roster_keys(store).reads_at_once:
            self._take_roster(*roster_names(store))

    def compose(self) -> ComposeResult:
        progress = self.progress
        dialog = Vertical(id="signoff-dialog")
        again = " again" if self.already else ""
        dialog.border_title = f"Sign off{again} {progress.lab}/{progress.exercise}"
        dialog.border_subtitle = "escape closes"
        who = self.student + (f" and {self.partner}" if self.partner else "")
        passed = sum(o.passed for o in progress.objectives)
        state = (
            "all objectives pass"
            if progress.passed
            else f"{passed} of {len(progress.objectives)} objectives pass: an override is needed"
        )
        with dialog:
            if self.already:
                yield Static(
                    f"Already signed off {self.already}. Signing again adds a second record; "
                    "the first stays in the log.",
                    id="signoff-already",
                    markup=False,
                )
            yield Static(f"{who}, driver {self.driver}; {state}", id="signoff-state", markup=False)
            notes = signoff_words(progress)
            if notes:
                yield Static(notes, id="signoff-evidence", markup=False)
            with Vertical(id="signoff-sign-off"):
                yield SignoffForm(
                    "signoff",
                    self.roster,
                    note_hint="optional; required with an override",
                    override_label="Override: sign off although objectives have not passed",
                )
                with Horizontal(classes="button-row"):
                    yield Static(classes="spacer")
                    yield Button("Sign off", id="signoff-sign", variant="primary", compact=True)
                    yield Button("Cancel", id="signoff-cancel", compact=True)
            with Vertical(id="signoff-next"):
                yield Static("", id="signoff-done", markup=False)
                yield Label("Who drives the next exercise?")
                with Horizontal(classes="button-row"):
                    for i, person in enumerate(self._people()):
                        yield Button(person, id=f"signoff-driver-{i}", compact=True)
            yield Static(self.roster_problem, id="signoff-status", markup=False)

    def _people(self) -> list[str]:
        return [self.student, self.partner] if self.partner else [self.student]

    def on_mount(self) -> None:
        follow_app(self)
        self.query_one("#signoff-next").display = False
        if self.roster_read.is_set():
            self._focus_first()
        else:
            self._say(READING_ROSTER)
            self.run_worker(self._read_roster_later(), group="signoff-roster")

    def _focus_first(self) -> None:
        if self.roster:
            self.query_one(SignoffForm).focus_first()

    def _take_roster(self, roster: list[str], problem: str) -> None:
        self.roster, self.roster_problem = roster, problem
        self.roster_read.set()

    async def _read_roster_later(self) -> None:
        self._take_roster(*await asyncio.to_thread(roster_names, self.store))
        self.query_one(SignoffForm).set_roster(self.roster)
        self._say(self.roster_problem)
        self._focus_first()

    # -- signing ---------------------------------------------------------------------------
    def _say_from_thread(self, message: str) -> None:
        self.app.call_from_thread(self._say, message)

    def _say(self, message: str) -> None:
        self.query_one("#signoff-status", Static).update(message)

    @on(Field.Capped, "#signoff-note")
    def _note_too_long(self, event: Field.Capped) -> None:
        self._say(f"a note is at most {event.limit} characters: the rest was not kept")

    @on(Input.Submitted, "#signoff-passphrase")
    @on(Input.Submitted, "#signoff-note")
    @on(Button.Pressed, "#signoff-sign")
    def _sign(self) -> None:
        if self.signed or self.signing is not None:
            return
        if not self.roster_read.is_set():
            self._say(READING_ROSTER)
            return
        if not self.roster:
            self._say(self.roster_problem)
            return
        form = self.query_one(SignoffForm)
        entry = form.entry()
        instructor = entry.instructor
        if instructor is None:
            self._say("choose the instructor")
            return
        progress = self.progress
        fields = RecordFields(
            student=self.student,
            lab=progress.lab,
            exercise=progress.exercise,
            driver=self.driver,
            partner=self.partner,
            evidence=Evidence.of_progress(progress),
            objectives_passed=progress.passed,
        )
        self._say(f"checking {instructor}'s key...")
        self.signing = self.run_worker(
            self._sign_off(instructor, fields, entry.override, entry.note, entry.passphrase),
            group="signoff",
            exit_on_error=False,
        )

    async def _sign_off(
        self, instructor: str, fields: RecordFields, override: bool, note: str, passphrase: str
    ) -> None:
        """Check, unlock the key (scrypt) and sign in a thread: the store may wait for its
        database (a save on its way, a database that does not answer) and the app keeps
        answering meanwhile."""
        try:
            _, record = await asyncio.to_thread(
                sign_off, self.store, instructor, passphrase, fields, override, note,
                say=self._say_from_thread,
            )  # fmt: skip
        except SignoffError as exc:
            self.query_one(SignoffForm).take_passphrase()
            self._say(str(exc))
        except Exception as exc:
            self._say(f"not signed: {exc}")
        else:
            self._signed(record.instructor, record.override)
            if self.on_signed is not None:
                self.on_signed(record)
            await self._record_driver()
        finally:
            self.signing = None
        if self.close_asked:
            self.action_close()

    async def _record_driver(self) -> None:
        progress = self.progress
        try:
            await asyncio.to_thread(
                self.store.progress.set_driver,
                self.student, self.partner, progress.lab, progress.exercise, self.driver,
            )  # fmt: skip
        except Exception as exc:
            self._say(f"signed, but the driver was not recorded: {exc}")
        else:
            if not self.roster_problem:
                self._say("")

    def _signed(self, instructor: str, override: bool) -> None:
        self.signed = True
        self.query_one("#signoff-sign-off").display = False
        self.query_one("#signoff-state").display = False
        self.query_one("#signoff-done", Static).update(
            f"Signed off by {instructor}{' (override)' if override else ''}."
        )
        self.query_one("#signoff-next").display = True
        self.query_one("#signoff-driver-0", Button).focus()

    @on(Button.Pressed, "#signoff-cancel")
    def action_close(self) -> None:
        """Close the dialog; while a key is being unlocked, once that attempt is over (so a
        wrong passphrase is always counted)."""
        if self.signing is not None:
            self.close_asked = True
            self._say("closing once the key is unlocked...")
            return
        self.dismiss(self.driver if self.signed else None)

    @on(Button.Pressed, ".button-row Button")
    def _driver(self, event: Button.Pressed) -> None:
        button_id = event.button.id or ""
        if not button_id.startswith("signoff-driver-"):
            return
        self.dismiss(self._people()[int(button_id.rsplit("-", 1)[1])])
