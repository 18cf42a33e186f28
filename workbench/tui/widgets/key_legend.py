"""The drive-by-wire key legend of a profile: always on screen."""

from __future__ import annotations

from typing import ClassVar

from textual.content import Content
from textual.reactive import reactive
from textual.widgets import Static

from workbench.control.manual import key_legend


class KeyLegend(Static):
    """w / a / s / d / space and what each does in the profile's key program."""

    DEFAULT_CSS = """
    KeyLegend {
        height: auto;
        padding: 0 1;
        border-top: solid $primary;
        border-title-color: $text-primary;
    }
    KeyLegend > .key-legend--key {
        color: $text-accent;
        text-style: bold;
    }
    """
    COMPONENT_CLASSES: ClassVar[set[str]] = {"key-legend--key"}

    profile: reactive[str] = reactive("unity", layout=True)

    def __init__(self, profile: str, *, id: str | None = None, classes: str | None = None):
        super().__init__(id=id, classes=classes, markup=False)
        self.set_reactive(KeyLegend.profile, profile)

    def on_mount(self) -> None:
        self.watch_profile(self.profile)

    def watch_profile(self, profile: str) -> None:
        self.border_title = f"Keys ({profile})"
        key_style = self.get_visual_style("key-legend--key", partial=True)
        lines = [
            Content.assemble((f"{'spc' if key == 'space' else key:<4}", key_style), text)
            for key, text in key_legend(profile)
        ]
        self.update(Content("\n").join(lines))
