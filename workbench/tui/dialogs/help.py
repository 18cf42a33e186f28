"""The help screen: every key of the workbench and what it does."""

from __future__ import annotations

from collections.abc import Callable
from typing import ClassVar

from rich.console import Group
from rich.table import Table
from rich.text import Text
from textual.app import ComposeResult
from textual.binding import Binding, BindingType
from textual.containers import Vertical, VerticalScroll
from textual.screen import ModalScreen
from textual.widgets import Static

from workbench.control.manual import key_legend

from ..keys import HELP_SECTIONS, KEY_TABLE, bindings


def _table() -> Table:
    table = Table.grid(padding=(0, 1), expand=True)
    table.add_column("key", no_wrap=True, style="bold", width=7)
    table.add_column("what", ratio=1)
    return table


def help_text(
    screens: list[tuple[str, list[Binding]]], profile: str, key_name: Callable[[Binding], str]
) -> Group:
    """Every key: the profile's drive keys, then each screen's keys grouped as
    :data:`~workbench.tui.keys.KEY_TABLE` says."""
    sections: list[tuple[str, Table]] = []
    drive = _table()
    for key, text in key_legend(profile):
        drive.add_row(key, text)
    sections.append((f"Drive ({profile} key program)", drive))
    tables: dict[str, Table] = {}
    shown: set[tuple[str, str]] = set()
    for screen, screen_bindings in screens:
        for binding in screen_bindings:
            if not binding.id or (screen, binding.id) in shown:
                continue  # the keys of one command (the arrows) are explained once
            shown.add((screen, binding.id))
            info = KEY_TABLE[binding.id]
            if info.group == "Drive":
                continue
            if info.group not in tables:
                tables[info.group] = _table()
                sections.append((info.group, tables[info.group]))
            what = Text.assemble((info.title, "bold"), ": ", info.explanation)
            tables[info.group].add_row(binding.key_display or key_name(binding), what)
    dialogs = _table()
    dialogs.add_row("tab", "Move between the fields and buttons of a dialog.")
    dialogs.add_row("enter", "Press the focused button; in a field, apply it.")
    dialogs.add_row("escape", "Close the dialog.")
    sections.append(("Dialogs", dialogs))
    parts: list[Text | Table] = []
    for i, (title, table) in enumerate(sections):
        parts.append(Text(("\n" if i else "") + title, style="bold underline"))
        parts.append(table)
    return Group(*parts)


class HelpScreen(ModalScreen[None]):
    """Every key, grouped, with a sentence each; escape or ? closes."""

    DEFAULT_CSS = """
    HelpScreen {
        align: center middle;
    }
    HelpScreen > #help-dialog {
        width: 100%;
        max-width: 100;
        height: 100%;
        max-height: 40;
        border: round $primary;
        border-title-color: $text-primary;
        border-subtitle-color: $text-muted;
        background: $surface;
        padding: 0 1;
    }
    HelpScreen VerticalScroll {
        height: 1fr;
        scrollbar-size-vertical: 1;
    }
    """

    BINDINGS: ClassVar[list[BindingType]] = [*bindings("help.close")]

    def __init__(self, profile: str, connect_hint: str = "") -> None:
        super().__init__()
        self.profile = profile
        #: how to reach the app's VIPLE endpoints from elsewhere (shown first when set)
        self.connect_hint = connect_hint

    def compose(self) -> ComposeResult:
        app = self.app
        dialog = Vertical(id="help-dialog")
        dialog.border_title = "Help: keys of the workbench"
        dialog.border_subtitle = "escape closes, arrows scroll"
        with dialog, VerticalScroll(id="help-scroll"):
            keys = [(heading, bindings(*ids)) for heading, ids in HELP_SECTIONS]
            hint = self.connect_hint
            if hint:
                yield Static(
                    Text.assemble(("Connect VIPLE", "bold underline"), "\n", hint, "\n"),
                    id="help-connect",
                )
            yield Static(help_text(keys, self.profile, app.get_key_display), id="help-text")

    def on_mount(self) -> None:
        self.query_one("#help-scroll").focus()

    def action_close(self) -> None:
        self.dismiss()
