"""Lines drawn straight to the compositor, for widgets whose styles leave their lines alone.

Textual's styles cache turns each line a widget renders into the line the screen shows: it adds
the border, padding, outline, tint, hatch, titles and opacity, then applies the app's line
filters and cuts the line to the crop. For a widget with none of those styles only the last two
steps change anything, and the cache's set-up for each call (the ancestors' colours, the
filters, the regions, the titles) costs more than the few lines a frame asks of a widget that
keeps its own lines (the maze view's rows, the transition log's entries). Such a widget draws
its lines with :func:`plain_lines` while :func:`plain_styles` holds, and Textual's way otherwise.
"""

from __future__ import annotations

from collections.abc import Callable

from textual.geometry import Region
from textual.strip import Strip
from textual.widget import Widget


def plain_styles(widget: Widget) -> bool:
    """Nothing of ``widget``'s styles changes its lines on their way to the screen."""
    styles = widget.styles
    return (
        not any(edge for edge, _ in styles.border)
        and not any(edge for edge, _ in styles.outline)
        and not any(styles.padding)
        and not styles.tint.a
        and styles.text_opacity == 1.0
        and (not styles.has_rule("hatch") or styles.hatch == "none")
        and widget.border_title is None
        and widget.border_subtitle is None
        and widget.opacity == 1.0
    )


def plain_lines(widget: Widget, crop: Region, line: Callable[[int], Strip]) -> list[Strip]:
    """The lines of ``crop`` (relative to the widget) as Textual's styles cache makes them of
    ``line(y)`` (each a whole line of the widget) for a widget with :func:`plain_styles`: the
    app's line filters applied, cut to the crop's columns."""
    strips = [line(y) for y in crop.line_range]
    filters = widget.app.get_line_filters()
    if filters:
        background = widget.background_colors[1]
        for line_filter in filters:
            strips = [strip.apply_filter(line_filter, background) for strip in strips]
    x1, x2 = crop.column_span
    if (x1, x2) != (0, widget.outer_size.width):
        strips = [strip.crop(x1, x2) for strip in strips]
    return strips
