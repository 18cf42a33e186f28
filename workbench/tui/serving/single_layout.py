"""A screen laid out once after a change of size, and drawn in that layout's frame.

When Textual lays a screen out (``Screen._refresh_layout``), it hands each widget the size the
layout gave it (``Widget._size_updated``), and that sets the widget's ``virtual_size`` (its
scrollable size: for a widget that does not scroll, its size). ``virtual_size`` is a reactive
declared with ``layout=True``, so every widget whose size the layout changed asks for a layout
of its own, and at the next idle moment the whole screen is laid out a second time, to the same
result. On the main screen that second layout cost as much as the first (some 10 ms of CPU),
each time the algorithm panel's last transition took a row more or less.

:class:`SingleLayout` lets a layout set the sizes it worked out without asking for another
layout. A widget whose size is set by code of its own (a log that grew, a maze view of a new
maze) still asks for one, as does everything else a layout may change and which does need one:

  * a scroll bar that comes or goes is a reactive of its own (``show_vertical_scrollbar``, also
    declared ``layout=True``), and so asks for the layout that makes room for it;
  * a scroll position the new size cuts short is a reactive of its own too (``scroll_y``), and
    scrolls the screen;
  * a widget that sets its ``virtual_size`` while it is being drawn (Textual's tree builds its
    lines then) does so after the layout: the layout is over when the screen draws
    (``_compositor_refresh``), and from there ``virtual_size`` asks for layouts again.

A scroll bar the layout placed does not ask for another layout either. Textual makes each bar
hidden (``display`` off), places it where its widget's ``show_vertical_scrollbar`` says, and then,
handing the widget its size, shows it; showing a widget asks for a layout, which placed it all
the same again (the transition log's bar, the first time a run shows the log, cost the main
screen a second layout, some 3 ms). Whether a bar is placed is its widget's
``show_*_scrollbar``, which asks for the layout a bar that comes or goes needs.

The widgets the layout asks to be redrawn (each resized one, and the scroll bars of every
scrolling one) are drawn in the layout's own frame rather than in a frame of their own after it,
which drew the same cells again. A scroll bar that the layout left as it was (Textual redraws
the bars of every scrolling widget at each layout: the maze view's too, when only the side panel
moved) is not drawn again at all.
"""

from __future__ import annotations

from typing import Any

from textual.geometry import Offset, Size
from textual.reactive import Reactive
from textual.screen import Screen
from textual.scrollbar import ScrollBar
from textual.widget import Widget

#: the one descriptor of every widget's ``virtual_size`` (a widget class may declare its own,
#: as the transition log does: that one never asks for a layout)
VIRTUAL_SIZE: Reactive[Size] = Widget.virtual_size
#: whether it asks for a layout when it changes, as Textual declares it
LAYS_OUT = VIRTUAL_SIZE._layout

#: what a scroll bar draws depends on
BarLook = tuple[int, int, float, bool, Offset | None, Size]


def bar_look(bar: ScrollBar) -> BarLook:
    return (
        bar.window_virtual_size,
        bar.window_size,
        bar.position,
        bar.mouse_over,
        bar.grabbed,
        bar.size,
    )


class SingleLayout(Screen):
    """A screen whose layout does not ask for a second one (see the module)."""

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        #: a layout is under way, with ``virtual_size`` asking for no layout
        self._sizing = False
        #: the scroll bars on the screen before the layout, not waiting to be redrawn, as they
        #: look
        self._bars_before: dict[ScrollBar, BarLook] = {}

    def _refresh_layout(self, size: Size | None = None, scroll: bool = False) -> None:
        if self._sizing:  # (Textual does not lay a screen out from within its layout)
            super()._refresh_layout(size, scroll)
            return
        self._bars_before = {
            widget: bar_look(widget)
            for widget in self._compositor.visible_widgets
            if isinstance(widget, ScrollBar) and not widget._repaint_required
        }
        whole = not scroll or bool(self._layout_widgets)  # (else Textual scrolls the screen)
        self._sizing = True
        VIRTUAL_SIZE._layout = False
        try:
            super()._refresh_layout(size, scroll)
        finally:
            self._end_sizing()
            self._bars_before = {}
        if whole:
            self._settle_bars()

    def _compositor_refresh(self) -> None:
        if self._sizing:
            # the layout ends where the screen is drawn (a widget drawn may set a virtual size)
            self._end_sizing()
            self._take_redraws()
        super()._compositor_refresh()

    def _end_sizing(self) -> None:
        if self._sizing:
            self._sizing = False
            VIRTUAL_SIZE._layout = LAYS_OUT

    def _settle_bars(self) -> None:
        """The scroll bars this layout placed and showed ask for no layout (see the module)."""
        for widget in self._compositor.visible_widgets:
            if isinstance(widget, ScrollBar) and widget._layout_required and widget.display:
                widget._layout_required = False

    def _take_redraws(self) -> None:
        """Have this frame draw what the layout asked to be redrawn (see the module)."""
        visible = self._compositor.visible_widgets
        for bar, look in self._bars_before.items():
            if bar._repaint_required and bar in visible and bar_look(bar) == look:
                bar._repaint_required = False
        asked = {widget for widget in visible if widget._repaint_required}
        if asked:
            self._compositor.update_widgets(asked)
            for widget in asked:
                widget._repaint_required = False
