"""A scrolling log of the transitions an algorithm has taken (newest at the bottom)."""

from __future__ import annotations

import textwrap
from collections.abc import Iterable

from textual.geometry import Size
from textual.reactive import Reactive
from textual.widget import Widget
from textual.widgets import Log

from workbench.fsm.machine import Transition

from ..textual_private import update_scrollbars
from .text import arrow, number


def values_text(values: dict[str, object], unit: str) -> str:
    return " ".join(
        f"{name}={number(v, unit) if isinstance(v, int | float) else v}"
        for name, v in values.items()
    )


class TransitionLog(Log):
    """Appends only the transitions it has not shown yet; cleared when a new run starts.

    An entry longer than the panel is wrapped onto indented lines below it (the log does not
    scroll sideways, so a cut entry would lose the state it went to and the values that fired
    it).

    It keeps its newest entry in sight: Textual's log follows only while it is already at its
    end, and the panel above it grows and shrinks with the last transition's text, which would
    leave it behind for good.

    A new entry redraws the log and its scroll bar, not the whole screen: Textual's log grows
    its scrollable size as a change of layout, and laying out the main screen again took most
    of a frame's work, at every transition of a running algorithm. (Its vertical scroll bar
    always shows, so a new line never changes the room the others have.)
    """

    virtual_size: Reactive[Size] = Reactive(Size(0, 0), layout=False)

    DEFAULT_CSS = """
    TransitionLog {
        height: 1fr;
        min-height: 2;
        padding: 0;
        background: transparent;
        scrollbar-size-vertical: 1;
        overflow-x: hidden;
    }
    """

    def __init__(self, *, id: str | None = None, classes: str | None = None) -> None:
        super().__init__(max_lines=200, id=id, classes=classes)
        self._run: object = None
        self._last: Transition | None = None

    def show(self, run: object, history: Iterable[Transition], unit: str, unicode: bool) -> None:
        """``run`` identifies the run (its controller); ``history`` is oldest first."""
        if run is not self._run:
            self._run = run
            self._last = None
            self.clear()
        entries = list(history)
        if not entries or entries[-1] is self._last:
            return
        start = 0
        if self._last is not None:
            for i in range(len(entries) - 1, -1, -1):
                if entries[i] is self._last:
                    start = i + 1
                    break
        self._last = entries[-1]
        go = arrow(unicode)
        # the panel's width (the log itself has none yet while it is hidden), less the scroll
        # bar's column
        panel = self.parent
        width = (panel.content_region.width if isinstance(panel, Widget) else 0) - 1
        lines: list[str] = []
        for t in entries[start:]:
            text = f"{t.time:6.1f} {t.source} {go} {t.target}"
            if t.values:
                text += f"  {values_text(dict(t.values), unit)}"
            if width < 16 or len(text) <= width:
                lines.append(text)
            else:
                lines += textwrap.wrap(text, width, subsequent_indent=" " * 7)
        self.write_lines(lines, scroll_end=False)
        self._follow()

    def watch_virtual_size(self) -> None:
        if self.is_mounted:
            update_scrollbars(self)

    def on_resize(self) -> None:
        self._follow()

    def _follow(self) -> None:
        # after the next layout, when the log's height and length are both known
        self.scroll_end(animate=False, immediate=False, x_axis=False)
