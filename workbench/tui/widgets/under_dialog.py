"""Knowing when a dialog is open over a widget's screen: the screen's keys do nothing then
(a dialog takes every key but the app's priority ones), so a widget that shows keys shows the
dialog's instead."""

from __future__ import annotations

from collections.abc import Callable

from textual.screen import ModalScreen, Screen
from textual.widget import Widget


def dialog_over(widget: Widget) -> Screen | None:
    """The dialog right over ``widget``'s screen, if one is open (None: the screen is on top,
    or another screen covers it whole)."""
    stack = widget.app.screen_stack
    screen = widget.screen
    if screen not in stack:
        return None
    above = stack.index(screen) + 1
    if above == len(stack) - 1 and isinstance(stack[above], ModalScreen):
        return stack[above]
    return None


class DialogWatch:
    """Calls ``changed`` after a dialog opens or closes over ``widget``'s screen (and, with
    ``keys``, after the open dialog's keys change, as its focus moves). Started on mount,
    stopped on unmount."""

    def __init__(self, widget: Widget, changed: Callable[[], object], keys: bool = False) -> None:
        self._widget = widget
        self._changed = changed
        self._keys = keys
        #: the dialog open over the widget's screen (None: none)
        self.dialog: Screen | None = None

    def start(self) -> None:
        self._widget.app.screen_change_signal.subscribe(self._widget, self._screen_changed)

    def stop(self) -> None:
        self._widget.app.screen_change_signal.unsubscribe(self._widget)
        self._follow(None)

    def _follow(self, dialog: Screen | None) -> None:
        if self._keys and self.dialog is not None:
            self.dialog.bindings_updated_signal.unsubscribe(self._widget)
        self.dialog = dialog
        if self._keys and dialog is not None:
            dialog.bindings_updated_signal.subscribe(self._widget, self._dialog_keys_changed)

    def _screen_changed(self, _screen: Screen) -> None:
        dialog = dialog_over(self._widget)
        if dialog is not self.dialog:
            self._follow(dialog)
            self._changed()

    def _dialog_keys_changed(self, screen: Screen) -> None:
        if screen is self.dialog and self._widget.is_attached:
            self._changed()
