"""A vertical scroll bar that draws its rows itself, as Textual's would (the transition log's)."""

from __future__ import annotations

from rich.color import Color
from rich.segment import Segment
from rich.style import Style
from textual.geometry import Region
from textual.scrollbar import ScrollBar, ScrollBarRender
from textual.strip import Strip

from .plain_lines import plain_lines, plain_styles

#: the colours Textual's renderer falls back on
BACK = Color.parse("#555555")
BAR = Color.parse("bright_magenta")


class LogScrollBar(ScrollBar):
    """Textual's vertical scroll bar, its rows made straight from the renderer's segments.

    Textual draws a scroll bar as a Rich renderable: through a console, its lines split and
    cropped, then through the styles cache, for a column a few cells high. A log's bar moves at
    every new line, and drawing it took longer than the log's own lines. The rows here are the
    segments of the bar's renderer (``ScrollBar.renderer``: the workbench's draws the ASCII
    mode's thumb) in the styles Textual gives them (the bar's own style under the renderer's),
    the app's line filters applied. A renderer that renders itself otherwise, or a bar styled
    with a border, padding and the like, is drawn Textual's way.
    """

    def __init__(self, *, thickness: int = 1) -> None:
        super().__init__(vertical=True, name="vertical", thickness=thickness)
        #: each row drawn, by its text and style (a bar has a few kinds of row: the same strips
        #: keep the line filters' work on them)
        self._row_strips: dict[tuple[str, Style | None, int], Strip] = {}

    def render_lines(self, crop: Region) -> list[Strip]:
        bar = self.render()
        if (
            not isinstance(bar, ScrollBarRender)
            or type(bar).__rich_console__ is not ScrollBarRender.__rich_console__
            or not bar.vertical
            or not isinstance(bar.style, Style)
            or not plain_styles(self)
            or self.styles.content_align != ("left", "top")
        ):
            return super().render_lines(crop)
        width, height = self.size
        drawn = bar.render_bar(
            size=height,
            window_size=bar.window_size,
            virtual_size=bar.virtual_size,
            position=bar.position,
            vertical=True,
            thickness=width,
            back_color=bar.style.bgcolor or BACK,
            bar_color=bar.style.color or BAR,
        )
        base = self.visual_style.rich_style
        kept = self._row_strips
        if len(kept) > 64:
            kept.clear()
        rows = []
        for text, style, _ in drawn.segments:
            if base:
                style = base + style
            row = kept.get((text, style, width))
            if row is None:
                row = kept[text, style, width] = Strip([Segment(text, style)], width)
            rows.append(row)
        return plain_lines(self, crop, rows.__getitem__)
