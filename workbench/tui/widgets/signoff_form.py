"""The fields of a sign-off: the instructor's name, their passphrase, a note and the override.

One form for both places an exercise is signed: the dialog at a workbench on one's own machine
and the request screen of the instructor's console. The screen around it owns the buttons and
what signing does; the form only holds what was typed. Its fields are named after the screen's
prefix (``{prefix}-instructor``, ``-passphrase``, ``-note``, ``-override``).
"""

from __future__ import annotations

from dataclasses import dataclass

from textual.app import ComposeResult
from textual.containers import Horizontal, Vertical
from textual.widgets import Input, Label, Select

from workbench.labs.signoff.signing import MAX_NOTE

from .field import Field
from .tick import Tick

#: what the screen says while the roster is read
READING_ROSTER = "reading the roster of instructors..."


@dataclass(frozen=True)
class SignoffEntry:
    """What the form holds: ``instructor`` is None until a name is chosen."""

    instructor: str | None
    passphrase: str
    note: str
    override: bool


class SignoffForm(Vertical):
    """Instructor, passphrase, note and override, one row each."""

    DEFAULT_CSS = """
    SignoffForm {
        height: auto;
    }
    SignoffForm .field-row {
        height: 1;
        margin-top: 1;
    }
    SignoffForm .field-row Label {
        width: 12;
    }
    SignoffForm .field-row Input, SignoffForm .field-row Select {
        width: 1fr;
    }
    SignoffForm Tick {
        margin-top: 1;
    }
    """

    def __init__(
        self, prefix: str, roster: list[str], *, note_hint: str, override_label: str
    ) -> None:
        super().__init__(id=f"{prefix}-form")
        self.prefix = prefix
        self._roster = roster
        self._note_hint = note_hint
        self._override_label = override_label

    def compose(self) -> ComposeResult:
        prefix = self.prefix
        with Horizontal(classes="field-row"):
            yield Label("Instructor")
            yield Select(
                self._options(self._roster),
                prompt="choose",
                value=self._roster[0] if len(self._roster) == 1 else Select.NULL,
                id=f"{prefix}-instructor",
                compact=True,
            )
        with Horizontal(classes="field-row"):
            yield Label("Passphrase")
            yield Field(password=True, id=f"{prefix}-passphrase", compact=True)
        with Horizontal(classes="field-row"):
            yield Label("Note")
            yield Field(
                placeholder=self._note_hint,
                id=f"{prefix}-note",
                compact=True,
                max_length=MAX_NOTE,
            )
        yield Tick(self._override_label, value=False, id=f"{prefix}-override", compact=True)

    @staticmethod
    def _options(roster: list[str]) -> list[tuple[str, str]]:
        return [(name, name) for name in roster]

    def _select(self) -> Select[str]:
        return self.query_one(f"#{self.prefix}-instructor", Select)

    def _input(self, part: str) -> Input:
        return self.query_one(f"#{self.prefix}-{part}", Input)

    def set_roster(self, roster: list[str]) -> None:
        """Offer ``roster`` (read after the form was shown); a roster of one is chosen."""
        self._roster = roster
        select = self._select()
        select.set_options(self._options(roster))
        if len(roster) == 1:
            select.value = roster[0]

    def focus_first(self) -> None:
        """The field to type in first: the passphrase when the name needs no choosing."""
        if len(self._roster) <= 1:
            self._input("passphrase").focus()
        else:
            self._select().focus()

    def entry(self) -> SignoffEntry:
        chosen = self._select().value
        return SignoffEntry(
            instructor=chosen if isinstance(chosen, str) else None,
            passphrase=self._input("passphrase").value,
            note=self._input("note").value,
            override=self.query_one(f"#{self.prefix}-override", Tick).value,
        )

    def take_passphrase(self) -> str:
        """The passphrase typed, cleared from its field (it is never kept on screen)."""
        field = self._input("passphrase")
        secret, field.value = field.value, ""
        return secret

    def focus_note(self) -> None:
        self._input("note").focus()
