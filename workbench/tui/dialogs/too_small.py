"""Shown instead of a broken layout while the terminal is smaller than the workbench needs."""

from __future__ import annotations

from textual.app import ComposeResult
from textual.screen import Screen
from textual.widgets import Static


class TooSmallScreen(Screen[None]):
    """Says how big the terminal is and how big it must be; goes away once it is."""

    DEFAULT_CSS = """
    TooSmallScreen {
        align: center middle;
        background: $background;
    }
    TooSmallScreen > Static {
        width: auto;
        max-width: 100%;
        height: auto;
        padding: 0 1;
        color: $text-warning;
        text-align: center;
    }
    """

    def __init__(self, minimum: tuple[int, int]) -> None:
        super().__init__()
        self.minimum = minimum

    def compose(self) -> ComposeResult:
        yield Static(id="too-small-text", markup=False)

    def on_mount(self) -> None:
        self.show_size(self.app.size.width, self.app.size.height)

    def on_screen_resume(self) -> None:
        # a screen pushed over this one while the terminal grew (the names dialog at start)
        # has gone: nothing is too small any more
        width, height = self.app.size
        if width >= self.minimum[0] and height >= self.minimum[1]:
            self.app.pop_screen()

    def show_size(self, width: int, height: int) -> None:
        min_w, min_h = self.minimum
        self.query_one(Static).update(
            f"The terminal is {width}x{height}: too small.\n"
            f"The workbench needs at least {min_w}x{min_h}.\n"
            "Enlarge the window (or make the font smaller).\n"
            "ctrl+q quits."
        )
