"""The "generate maze" dialog: size in cells, seed, style and exits, checked before it closes."""

from __future__ import annotations

from textual import on
from textual.app import ComposeResult
from textual.containers import Horizontal, Vertical
from textual.widgets import Button, Input, Label, Select, Static

from workbench.sim.editing import EditorError, GenerateOptions
from workbench.sim.generate import EXITS, MAX_CELLS, MIN_CELLS, STYLES

from ..plain import follow_app
from ..widgets.field import Field
from .frame import Dialog

STYLE_HELP = {"perfect": "perfect (one path)", "braid": "braid (loops, no dead ends)"}
EXIT_HELP = {
    "boundary": "boundary (gap in the outer wall)",
    "center": "center (micromouse goal)",
    "none": "none (free exploration)",
}


class GenerateDialog(Dialog[GenerateOptions | None]):
    """Asks for generator options; dismisses with :class:`GenerateOptions` or None."""

    def __init__(self, options: GenerateOptions) -> None:
        super().__init__()
        self._options = options

    def compose(self) -> ComposeResult:
        o = self._options
        with Vertical(id="dialog") as box:
            box.border_title = "Generate maze"
            yield Static(
                f"W x H cells make a (2W+1) x (2H+1) block maze ({MIN_CELLS}-{MAX_CELLS} "
                "cells a side). The same seed always gives the same maze.",
                classes="help",
            )
            with Horizontal(classes="field"):
                yield Label("Width")
                yield Field(str(o.width), id="width", compact=True, restrict=r"\d*")
            with Horizontal(classes="field"):
                yield Label("Height")
                yield Field(str(o.height), id="height", compact=True, restrict=r"\d*")
            with Horizontal(classes="field"):
                yield Label("Seed")
                yield Field(str(o.seed), id="seed", compact=True, restrict=r"\d*")
            with Horizontal(classes="field"):
                yield Label("Style")
                yield Select(
                    [(STYLE_HELP.get(s, s), s) for s in STYLES],
                    value=o.style,
                    allow_blank=False,
                    compact=True,
                    id="style",
                )
            with Horizontal(classes="field"):
                yield Label("Exit")
                yield Select(
                    [(EXIT_HELP.get(e, e), e) for e in EXITS],
                    value=o.exit,
                    allow_blank=False,
                    compact=True,
                    id="exit",
                )
            yield Static("", id="error", classes="-empty")
            with Horizontal(id="buttons"):
                yield Button("Generate", id="ok", variant="primary", compact=True)
                yield Button("Cancel", id="cancel", compact=True)

    def on_mount(self) -> None:
        follow_app(self)
        self.query_one("#width", Input).focus()

    @on(Input.Submitted)
    @on(Button.Pressed, "#ok")
    def submit(self, event: Input.Submitted | Button.Pressed) -> None:
        event.stop()
        try:
            options = GenerateOptions.parse(
                self.query_one("#width", Input).value,
                self.query_one("#height", Input).value,
                self.query_one("#seed", Input).value,
                str(self.query_one("#style", Select).value),
                str(self.query_one("#exit", Select).value),
            )
        except EditorError as exc:
            self.show_error(str(exc))
            return
        self.dismiss(options)
