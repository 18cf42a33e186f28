"""A scrolling log of the transitions an algorithm has taken (newest at the bottom)."""

from __future__ import annotations

import re
import textwrap
from collections.abc import Iterable

from rich.cells import cell_len
from rich.style import Style
from rich.text import Text
from textual.geometry import Region, Size
from textual.reactive import Reactive
from textual.scrollbar import ScrollBar
from textual.strip import Strip
from textual.widget import Widget
from textual.widgets import Log

from workbench.fsm.machine import Transition

from ..textual_private import own_vertical_scrollbar, update_scrollbars
from .log_scroll_bar import LogScrollBar
from .plain_lines import plain_lines, plain_styles
from .text import arrow, number

#: the characters Textual's log shows as a replacement character
CONTROL = re.compile("[\u0000-\u0014]")


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

    Each entry's line is drawn once, as Textual's log draws it, and kept: a new entry scrolls
    the log by a line, and Textual's log drew every line it shows again for it (and each line
    through Textual's styles cache, which the log's plain styles leave as they are).
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
        #: each line's text as drawn in ``_drawn_in`` (the log's style when it was drawn)
        self._drawn: dict[str, Strip] = {}
        self._drawn_in: Style | None = None

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
        # at once, so the frame that draws the new entry draws the log scrolled to it (after the
        # next refresh, that frame drew the log as it was and the next one scrolled it); when
        # the panel above changes its rows in the same tick, the resize follows again
        self.scroll_end(animate=False, immediate=True, x_axis=False)

    @property
    def vertical_scrollbar(self) -> ScrollBar:
        """The log's scroll bar: one that draws its rows itself (it moves at every entry)."""
        return own_vertical_scrollbar(
            self, lambda: LogScrollBar(thickness=self.scrollbar_size_vertical)
        )

    def render_lines(self, crop: Region) -> list[Strip]:
        """The lines of ``crop``, each entry's line as it was drawn the first time (a selection
        is drawn Textual's way, as is the log styled with a border, padding, ...)."""
        if self.text_selection is not None or not plain_styles(self):
            return super().render_lines(crop)
        style = self._style_now()
        scroll_x, scroll_y = self.scroll_offset
        width = self.size.width
        return plain_lines(self, crop, lambda y: self._line(scroll_y + y, scroll_x, width, style))

    def render_line(self, y: int) -> Strip:
        if self.text_selection is not None:
            return super().render_line(y)
        scroll_x, scroll_y = self.scroll_offset
        return self._line(scroll_y + y, scroll_x, self.size.width, self._style_now())

    def _style_now(self) -> Style:
        """The log's style, with the lines drawn in another style forgotten."""
        style = self.visual_style.rich_style  # (Textual keeps it until the styles change)
        if style != self._drawn_in:
            self._drawn.clear()
            self._drawn_in = style
        return style

    def _line(self, index: int, scroll_x: int, width: int, style: Style) -> Strip:
        """Line ``index`` of the log, as Textual's log draws it when nothing is selected."""
        lines = self.lines
        if index >= len(lines):
            return Strip.blank(width, style)
        text = lines[index]
        strip = self._drawn.get(text)
        if strip is None:
            if len(self._drawn) > 2 * len(lines):
                self._drawn.clear()  # (entries pruned, or of runs before)
            shown = CONTROL.sub("\ufffd", text.expandtabs())
            line = Text(shown, no_wrap=True)
            line.stylize(style)
            strip = self._drawn[text] = Strip(line.render(self.app.console), cell_len(shown))
        return strip.crop_extend(scroll_x, scroll_x + width, style).apply_offsets(scroll_x, index)

    def watch_virtual_size(self) -> None:
        if self.is_mounted:
            update_scrollbars(self)

    def on_resize(self) -> None:
        self._follow()

    def _follow(self) -> None:
        # after the layout, when the log's height and length are both known
        self.scroll_end(animate=False, immediate=False, x_axis=False)
