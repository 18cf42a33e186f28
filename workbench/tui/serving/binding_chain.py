"""A screen whose key bindings are looked up once, not for every key.

For each key press Textual builds the screen's binding chain afresh: a copy of the bindings of
the focused widget and of each of its ancestors, each copy filtered by asking every widget
nearer the focus whether it would take each key itself. On the main screen (the transition log
focused, five containers up to the app, some thirty bindings) that is about 150 calls and six
copies per key, the largest part of what a drive key costs while a student drives at 20 keys a
second.

:class:`CachedBindingChain` keeps the chain Textual builds and hands it out again until
something it was built from changes: the focused widget (or its being loaded), the widgets and
binding maps from it up to the app, or the app's keymap. A widget's ancestors stay the same
while it is mounted (Textual moves no widget to another parent, and mounts a removed one no
more) and each node's binding map is made with the node, so the focused widget and its parent
stand for the whole chain: checking it is a few reads, not a walk up to the app for every key.
Any ``refresh_bindings`` (Textual's signal that bindings may have changed) drops it too. The
chain is only read by Textual (it looks keys up in it), never changed, so handing out the same
one is safe.

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
        keymap = self.app._keymap
        # a mounted widget keeps its parent (and so every ancestor) until it is removed, and a
        # node's binding map is made once, with the node: the focused widget and its parent
        # stand for the nodes of the chain and their maps
        if focused is None:
            key: tuple[object, ...] = (None, None, False, id(keymap), len(keymap))
        else:
            key = (focused, focused._parent, focused.loading, id(keymap), len(keymap))
        chain = self._chain
        if chain is None or key != self._chain_key:
            chain = self._chain = super()._binding_chain
            self._chain_key = key
        return chain

    def refresh_bindings(self) -> None:
        self._chain_key = None
        super().refresh_bindings()
