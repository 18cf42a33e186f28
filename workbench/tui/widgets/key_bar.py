"""The compact key bar at the foot of the main and labs screens: Textual's footer, with each
key made compact before it is first styled.

Textual's footer styles every key as it mounts it and then again, for each key, when the key
takes the footer's ``compact`` setting and with it the ``-compact`` class: a third of the CPU
a served app spends before its first screen went on styling the footer's keys. Here the keys
carry the class from the start, so the second styling finds nothing to change.
"""

from __future__ import annotations

from textual.app import ComposeResult
from textual.widgets import Footer

from ..serving.internals import FooterKey


class KeyBar(Footer):
    """A compact footer of the screen's keys (without the command palette's key)."""

    def __init__(self, *, id: str | None = None, classes: str | None = None) -> None:
        super().__init__(id=id, classes=classes, compact=True, show_command_palette=False)

    def compose(self) -> ComposeResult:
        for widget in super().compose():
            if isinstance(widget, FooterKey):
                widget.set_class(True, "-compact", update=False)
            yield widget
