"""The private parts of Textual the rest of the TUI needs, each behind a name saying what it
gives, so that they are all in this package (see its description) and checked in one place
(``tests/unit/test_textual_internals.py``)."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from textual import events
from textual._context import active_app
from textual.app import App
from textual.binding import BindingsMap
from textual.content import Content
from textual.dom import DOMNode
from textual.geometry import Size
from textual.scrollbar import ScrollBar
from textual.widget import Widget
from textual.widgets import Checkbox, Footer, Input, RadioButton
from textual.widgets._footer import FooterKey
from textual.widgets._toggle_button import ToggleButton

__all__ = [
    "DrawnCheckbox",
    "DrawnRadioButton",
    "FooterKey",
    "KeyFirstInput",
    "bindings_of",
    "current_app",
    "end_with_error",
    "footer_ready",
    "handled_size",
    "own_vertical_scrollbar",
    "update_scrollbars",
]


def current_app() -> App[Any] | None:
    """The app whose code runs now (None outside any app)."""
    try:
        return active_app.get()
    except LookupError:
        return None


def bindings_of(node: DOMNode) -> BindingsMap:
    """The node's own key bindings, as Textual merged them from its class and its bases."""
    return node._bindings


def end_with_error(app: App[Any], error: Exception) -> None:
    """End the app with ``error`` shown, as Textual does for an error in the app's own code."""
    app._handle_exception(error)


def footer_ready(footer: Footer) -> bool:
    """Whether the footer has read its screen's bindings (its keys can be composed)."""
    return bool(footer._bindings_ready)


def update_scrollbars(widget: Widget) -> None:
    """Bring a scrolling widget's scroll bars (whether they show, their thumbs) and its scroll
    position up to its virtual size now, as Textual does when it lays the widget out."""
    widget._scroll_update(widget.virtual_size)


def own_vertical_scrollbar(widget: Widget, make: Callable[[], ScrollBar]) -> ScrollBar:
    """The widget's vertical scroll bar, made by ``make`` the first time it is asked for, where
    Textual makes its own ``ScrollBar`` (for a widget's ``vertical_scrollbar`` property), and
    started as Textual starts its own: hidden until the widget's first layout shows it."""
    bar = widget._vertical_scrollbar
    if bar is None:
        bar = widget._vertical_scrollbar = make()
        bar.display = False
        widget.app._start_widget(widget, bar)
    return bar


def handled_size(app: App[Any]) -> Size | None:
    """The terminal size the app has handled a resize to (None before the first)."""
    return app._size


class KeyFirstInput(Input):
    """Textual's ``Input``, which asks :meth:`take_key` first about each key that reaches it."""

    async def take_key(self, event: events.Key) -> bool:
        """Handle ``event`` here and say so, or say no: the input then handles it as usual."""
        return False

    async def _on_key(self, event: events.Key) -> None:
        if not await self.take_key(event):
            await super()._on_key(event)


class DrawnToggle(ToggleButton):
    """Textual's toggle button (a check box, a radio button) with its box drawn by
    :meth:`box`."""

    def box(self) -> Content:
        """The box as drawn before the label (Textual's own, unless a subclass says)."""
        return super()._button

    @property
    def _button(self) -> Content:
        return self.box()


class DrawnCheckbox(Checkbox, DrawnToggle):
    """Textual's ``Checkbox`` with its box drawn by :meth:`box`."""


class DrawnRadioButton(RadioButton, DrawnToggle):
    """Textual's ``RadioButton`` with its box drawn by :meth:`box`."""
