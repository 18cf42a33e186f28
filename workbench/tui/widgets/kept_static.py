"""A ``Static`` that keeps the lines it drew for the contents it shows again and again."""

from __future__ import annotations

from collections.abc import Hashable

from textual.cache import LRUCache
from textual.content import Content
from textual.geometry import Region
from textual.strip import Strip
from textual.widgets import Static

from .plain_lines import plain_styles


class KeptStatic(Static):
    """Textual's ``Static``, which draws a content it drew before from the lines it kept.

    The algorithm panel's row of states shows one of a few contents (the machine's states, one
    of them highlighted), a new one at every transition; Textual's ``Static`` wraps and draws
    its content afresh each time, which took as long as the rest of a transition's frame. The
    lines are kept for what Textual draws them from: the content (its text and its styled
    spans), the widget's size, the crop, its style, background, alignment and wrapping, and the
    app's line filters. A selection, a link under the mouse, a content that is not a
    ``Content``, or a border, padding and the like (:func:`plain_styles`) is drawn Textual's
    way.
    """

    def __init__(self, *, keep: int = 16, id: str | None = None) -> None:
        super().__init__(id=id, markup=False)
        self._kept: LRUCache[Hashable, list[Strip]] = LRUCache(keep)

    def render_lines(self, crop: Region) -> list[Strip]:
        visual = self.visual
        if (
            not isinstance(visual, Content)
            or self.text_selection is not None
            or (self.auto_links and self.hover_style.link_id)
            or not plain_styles(self)
        ):
            return super().render_lines(crop)
        styles = self.styles
        key = (
            visual.plain,
            tuple(visual.spans),
            self.size,
            crop,
            self.visual_style,
            self.background_colors,
            styles.text_align,
            styles.content_align,
            styles.text_wrap,
            styles.text_overflow,
            styles.line_pad,
            tuple(self.app.get_line_filters()),
        )
        lines = self._kept.get(key)
        if lines is None:
            lines = self._kept[key] = super().render_lines(crop)
        return lines
