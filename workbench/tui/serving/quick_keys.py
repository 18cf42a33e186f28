"""Typed keys that a screen runs straight from the served session's input, without a key event.

A student driving over SSH types up to twenty keys a second, nearly all of them a few letters
the main screen binds with priority (``w``, ``a``, ``d``, space). As key events, each was made,
queued for the app, woken for, dispatched, looked up in the binding chain, its action string
parsed and checked, the action invoked through Textual's signature-inspecting helper, and each
message then followed by the idle round every message pump makes. Measured with
``bench/tui_cpu.py``, that was about a quarter of what a served app costs while a student drives.

:class:`QuickKeys` (a screen) answers, for a typed key, with the action Textual would run for it
when that is one of the screen's own ``QUICK_ACTIONS`` (plain methods that only change the
station and draw):

  * the binding is the key's first priority binding in the chain from the app down to the
    focused widget, the order Textual tries them in; any other binding first (the app's own,
    a widget's) and the key goes the usual way;
  * its action is parsed once per binding chain, and ``check_action`` is asked at each press,
    as Textual asks;
  * only when every message pump a key passes through (the focused widget, its ancestors, the
    screen and the app) has nothing queued: a key taken at once never overtakes one typed
    before it that is still on its way.

The served app's terminal driver (``terminal_driver.py``) offers each typed key to the app first
(``WorkbenchApp.take_typed_key``), which runs the action with what Textual does for any key
press at the app (the app focused, a tooltip cleared) and what the workbench does (the clock
woken and nudged).
"""

from __future__ import annotations

from collections.abc import Callable
from functools import partial
from typing import Any, ClassVar

from textual.actions import parse
from textual.app import App
from textual.binding import BindingsMap
from textual.dom import DOMNode
from textual.screen import Screen
from textual.widgets import Tooltip

from .binding_chain import CachedBindingChain

#: what a key is bound to, for the quick path: the action's name and parameters and the call
#: that runs it, or None when its first priority binding is not a quick action of the screen
QuickBinding = tuple[str, tuple[object, ...], Callable[[], object]] | None


class QuickKeys(CachedBindingChain):
    """A screen whose quick actions run straight from a typed key (see the module)."""

    #: the actions run straight from a key: synchronous ``action_*`` methods of the screen
    QUICK_ACTIONS: ClassVar[frozenset[str]] = frozenset()

    _quick_chain: list[tuple[DOMNode, BindingsMap]] | None = None
    _quick_table: dict[str, QuickBinding]
    #: the message pumps of the chain, from the focused widget up
    _quick_nodes: tuple[DOMNode, ...] = ()

    def quick_action(self, key: str) -> Callable[[], object] | None:
        """The action to run for ``key`` now, or None for the usual way of a key event."""
        chain = self._binding_chain
        if chain is not self._quick_chain:
            self._quick_table = self._quick_bindings(chain)
            self._quick_nodes = tuple(node for node, _ in chain)
            self._quick_chain = chain
        found = self._quick_table.get(key)
        if found is None:
            return None
        for node in self._quick_nodes:
            if node.message_queue_size:
                return None  # (on the way: something typed before it may still be going)
        name, params, action = found
        if not self.check_action(name, params):
            return None
        return action

    def nothing_on_the_way(self) -> bool:
        """Whether every message pump a key passes through has nothing queued (else a key
        taken at once could overtake one that is still on its way)."""
        return not any(node.message_queue_size for node, _ in self._binding_chain)

    def _quick_bindings(self, chain: list[tuple[DOMNode, BindingsMap]]) -> dict[str, QuickBinding]:
        table: dict[str, QuickBinding] = {}
        for node, bindings in reversed(chain):  # from the app down, as Textual looks
            for key, key_bindings in bindings.key_to_bindings.items():
                for binding in key_bindings:
                    if not binding.priority or key in table:
                        continue
                    namespace, name, params = parse(binding.action)
                    quick = node is self and not namespace and name in self.QUICK_ACTIONS
                    action = partial(getattr(self, f"action_{name}"), *params) if quick else None
                    table[key] = (name, params, action) if action is not None else None
        return table


def as_key_press(app: App[Any], screen: Screen[Any]) -> None:
    """What Textual does at the app for any key press, done for a key taken at once: the app
    focused, and a tooltip shown on ``screen`` cleared."""
    if not app.app_focus:
        app.app_focus = True
    for child in screen.children:  # (looked for here: Textual's lookup words an error for none)
        if isinstance(child, Tooltip) and child.display and app.focused is not None:
            screen._clear_tooltip()
            return
