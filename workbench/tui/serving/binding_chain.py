"""A screen whose key bindings are looked up once, not for every key.

For each key press Textual builds the screen's binding chain afresh: a copy of the bindings of
the focused widget and of each of its ancestors, each copy filtered by asking every widget
nearer the focus whether it would take each key itself. On the main screen (the transition log
focused, five containers up to the app, some thirty bindings) that is about 150 calls and six
copies per key, the largest part of what a drive key costs while a student drives at 20 keys a
second.

:class:`CachedBindingChain` keeps the chain Textual builds and hands it out again until
something it was built from changes: the focused widget (or its being loaded), the widgets and
binding maps from it up to the app, or the app's keymap. Any ``refresh_bindings`` (Textual's
signal that bindings may have changed) drops it too. The chain is only read by Textual (it
looks keys up in it), never changed, so handing out the same one is safe.

Only for screens whose widgets decide from the key alone whether they take it
(``check_consume_key``), as every widget of the main screen does.
"""

from __future__ import annotations

from textual.binding import BindingsMap
from textual.dom import DOMNode
from textual.screen import Screen


class CachedBindingChain(Screen):
    """A screen that builds its binding chain only when what it depends on changed."""

    _chain_key: tuple[object, ...] | None = None
    _chain: list[tuple[DOMNode, BindingsMap]] | None = None

    @property
    def _binding_chain(self) -> list[tuple[DOMNode, BindingsMap]]:
        focused = self.focused
        nodes = (self, self.app) if focused is None else tuple(focused.ancestors_with_self)
        keymap = self.app._keymap
        key = (
            focused,
            focused is not None and focused.loading,
            id(keymap),
            len(keymap),
            *nodes,
            *(id(node._bindings) for node in nodes),
        )
        chain = self._chain
        if chain is None or key != self._chain_key:
            chain = self._chain = super()._binding_chain
            self._chain_key = key
        return chain

    def refresh_bindings(self) -> None:
        self._chain_key = None
        super().refresh_bindings()
