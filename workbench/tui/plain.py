"""ASCII mode for the parts Textual draws itself: scroll bars, drop-down arrows, list bullets,
the command palette, and prose written with typographic characters.

The panels and dialogs of the workbench pick their marks from the app's ``unicode`` setting;
the widgets Textual draws use glyphs of their own (block elements, triangles, an emoji), which
a plain terminal shows as boxes. Each is replaced here, in one place, while the app is in ASCII
mode (the app's ``-ascii`` class); the stylesheet does the same for borders.
"""

from __future__ import annotations

from typing import ClassVar

from textual.command import CommandPalette, SearchIcon
from textual.dom import DOMNode
from textual.scrollbar import ScrollBar, ScrollBarRender
from textual.widgets import Markdown, Static

from .textual_private import current_app

#: typographic characters of prose (lab texts, algorithm descriptions) and their ASCII spelling
PROSE = str.maketrans(
    {
        "°": " deg",
        "…": "...",
        "—": "--",
        "–": "-",
        "−": "-",
        "±": "+/-",
        "‘": "'",
        "’": "'",
        "“": '"',
        "”": '"',
        "×": "x",
        "→": "->",
        "←": "<-",
        "≤": "<=",
        "≥": ">=",
        "≠": "!=",
        "•": "*",
        "·": "-",
        "✓": "+",
        "✗": "x",
        "\u00a0": " ",
    }
)


def ascii_mode() -> bool:
    """Whether the app drawing now is in ASCII mode."""
    app = current_app()
    return app is not None and app.has_class("-ascii")


def prose(text: str, unicode: bool) -> str:
    """``text`` as written (Unicode) or spelt in ASCII; any other character becomes ``?``."""
    if unicode:
        return text
    text = text.translate(PROSE)
    if text.isascii():
        return text
    return text.encode("ascii", "replace").decode("ascii")


class _BlankBars(ScrollBarRender):
    VERTICAL_BARS: ClassVar[list[str]] = [" "] * 8
    HORIZONTAL_BARS: ClassVar[list[str]] = [" "] * 8


class WorkbenchScrollBarRender(ScrollBarRender):
    """Textual's scroll bar; in ASCII mode its thumb is whole reverse-video cells (no eighth
    blocks), so it is plain spaces on any terminal."""

    @classmethod
    def render_bar(cls, *args, **kwargs):
        if ascii_mode():
            return _BlankBars.render_bar(*args, **kwargs)
        return super().render_bar(*args, **kwargs)


ScrollBar.renderer = WorkbenchScrollBarRender

#: the drop-down arrows of a Select, by class, in ASCII
ARROWS = {"down-arrow": ("▼", "v"), "up-arrow": ("▲", "^")}
#: Markdown's list bullets, in ASCII
ASCII_BULLETS = ["* ", "- ", "+ ", "* ", "- "]


def follow(root: DOMNode, unicode: bool) -> None:
    """Redraw the Textual-drawn glyphs under ``root`` (a screen, or a widget just mounted)
    in Unicode or ASCII."""
    for name, (fancy, plain) in ARROWS.items():
        for arrow in root.query(f".{name}").results(Static):
            arrow.update(fancy if unicode else plain)
    for text in root.query(Markdown):
        text.BULLETS = Markdown.BULLETS if unicode else ASCII_BULLETS


class PlainCommandPalette(CommandPalette):
    """The command palette with a ``>`` for its search icon and ``...`` in its prompt."""

    def __init__(self) -> None:
        super().__init__(placeholder="Search for commands...", id="--command-palette")

    def on_mount(self) -> None:
        self.query_one(SearchIcon).icon = ">"


def drawn_in_unicode(node: DOMNode) -> bool:
    """Whether ``node``'s app draws in Unicode now."""
    return not node.app.has_class("-ascii")


def follow_app(root: DOMNode) -> None:
    """:func:`follow` the app's setting, for a screen or widget as it mounts."""
    follow(root, drawn_in_unicode(root))
