"""A few lines of text that repaint line by line: only the lines whose text changed are sent.

Panels that follow a running robot (time, distance, sensor readings) change one or two lines at
a time; a ``Static`` would repaint its whole region on every change.
"""

from __future__ import annotations

import textwrap
from collections.abc import Sequence

from rich.segment import Segment
from rich.style import Style
from rich.text import Text
from textual.geometry import Region, Size
from textual.strip import Strip
from textual.widget import Widget


class TextLines(Widget):
    """Lines of plain text (or Rich ``Text``), one per row, cached as strips.

    With ``wrap``, a plain line longer than the widget is wrapped at spaces onto the rows
    below it (indented by two), so nothing is cut at a narrow terminal.
    """

    DEFAULT_CSS = """
    TextLines {
        height: auto;
    }
    """

    def __init__(
        self,
        lines: Sequence[str | Text] = (),
        *,
        wrap: bool = False,
        id: str | None = None,
        classes: str | None = None,
    ) -> None:
        super().__init__(id=id, classes=classes)
        self.wrap = wrap
        self._source: list[str | Text] = list(lines)
        self._lines: list[str | Text] = list(lines)
        self._strips: list[Strip | None] = [None] * len(self._lines)
        self._width = 0
        #: the widget's own style, kept until the styles change (Textual works it out afresh
        #: from every ancestor's on each call)
        self._base: Style | None = None

    def _rows(self, lines: Sequence[str | Text], width: int) -> list[str | Text]:
        """The rows ``lines`` take at ``width`` (themselves, unless wrapped)."""
        if not self.wrap or width < 8:
            return list(lines)
        rows: list[str | Text] = []
        for line in lines:
            if isinstance(line, Text) or len(line) <= width:
                rows.append(line)
            else:
                rows += textwrap.wrap(line, width, subsequent_indent="  ", break_on_hyphens=False)
        return rows

    @property
    def lines(self) -> tuple[str | Text, ...]:
        return tuple(self._source)

    def set_lines(self, lines: Sequence[str | Text]) -> None:
        """Show ``lines``; repaint only the rows that changed (re-layout when the count does)."""
        self._source = list(lines)
        lines = self._rows(lines, self.size.width)
        if len(lines) != len(self._lines):
            self._lines = lines
            self._strips = [None] * len(lines)
            self.refresh(layout=True)
            return
        width = self.size.width
        changed = []
        for y, (old, new) in enumerate(zip(self._lines, lines, strict=True)):
            if old != new:
                self._lines[y] = new
                self._strips[y] = None
                changed.append(Region(0, y, width, 1))
        if changed and self.is_mounted:
            self.refresh(*changed)  # one refresh for all the changed rows

    def notify_style_update(self) -> None:
        super().notify_style_update()
        self._base = None
        self._strips = [None] * len(self._lines)

    def get_content_height(self, container: Size, viewport: Size, width: int) -> int:
        return len(self._rows(self._source, width))

    def get_content_width(self, container: Size, viewport: Size) -> int:
        return max((len(str(line)) for line in self._source), default=0)

    def render_line(self, y: int) -> Strip:
        width = self.size.width
        if width != self._width:
            self._width = width
            self._lines = self._rows(self._source, width)
            self._strips = [None] * len(self._lines)
        base = self._base
        if base is None:
            base = self._base = self.rich_style
        if not 0 <= y < len(self._lines):
            return Strip.blank(width, base)
        strip = self._strips[y]
        if strip is None:
            line = self._lines[y]
            text = line if isinstance(line, Text) else Text(line, no_wrap=True, overflow="crop")
            segments = [
                Segment(seg.text, base + seg.style if seg.style else base)
                for seg in text.render(self.app.console)
                if seg.text != "\n"
            ]
            strip = Strip(segments).adjust_cell_length(width, base)
            self._strips[y] = strip
        return strip
