"""Asks the instructor whether the partner a request names worked on it and agrees, before
the sign-off is made: the pair (y), the student alone (n), or not yet (escape)."""

from __future__ import annotations

from typing import ClassVar

from textual import on
from textual.app import ComposeResult
from textual.binding import BindingType
from textual.containers import Horizontal, Vertical
from textual.widgets import Button, Static

from ..keys import bindings
from .frame import Dialog


class PairDialog(Dialog[bool | None]):
    """Dismisses with True (sign for the pair), False (the student alone) or None. When the
    partner cannot be on the sign-off (``problem``), only the student alone is offered."""

    BINDINGS: ClassVar[list[BindingType]] = [*bindings("pair.agree", "pair.alone")]

    def __init__(self, student: str, partner: str, problem: str = "") -> None:
        super().__init__()
        self._student = student
        self._partner = partner
        self._problem = problem

    def compose(self) -> ComposeResult:
        with Vertical(id="dialog") as box:
            box.border_title = "Confirm the pair"
            yield Static(
                f"{self._student} names {self._partner} as their partner. A sign-off for the "
                f"pair is also {self._partner}'s: sign for both only if {self._partner} "
                "worked on it and agrees (ask them).",
                classes="help",
                markup=False,
            )
            if self._problem:
                yield Static(self._problem, id="error", markup=False)
            with Horizontal(id="buttons"):
                if not self._problem:
                    yield Button("Pair (y)", id="pair", variant="primary", compact=True)
                yield Button(f"{self._student} alone (n)", id="alone", compact=True)
                yield Button("Cancel", id="cancel", compact=True)

    def on_mount(self) -> None:
        self.query_one("#alone" if self._problem else "#pair", Button).focus()

    def action_choose(self, pair: bool) -> None:
        if pair and self._problem:
            return
        self.dismiss(pair)

    @on(Button.Pressed, "#pair")
    def _pair(self, event: Button.Pressed) -> None:
        event.stop()
        self.dismiss(True)

    @on(Button.Pressed, "#alone")
    def _alone(self, event: Button.Pressed) -> None:
        event.stop()
        self.dismiss(False)
