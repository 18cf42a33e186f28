"""A key's bindings looked up where the key was delivered, not where the focus is later.

Textual runs a key's *priority* bindings as the app takes the key from its queue, and hands the
key to the focused widget otherwise. The key then climbs from that widget to the app, each
widget taking it in its own turn; only at the app are its ordinary bindings looked up (a check
box's space, a button's enter), and Textual looks them up from the widget focused *then*.

Keys that arrive together (over SSH a typist's keys come in one packet) are all taken by the
app before the first has climbed back: a space for a check box and a shift+tab right after it,
and the app's tab and shift+tab (priority bindings, so that the characters typed after a tab go
into the next field) move the focus first. The space was then looked up from the widget the
focus moved to, which has no binding for it, and was lost: the box stayed unticked.

:class:`DeliveredKeys` keeps, as each key is handed on, the binding chain of the screen at that
moment (the focused widget and its ancestors up to the first modal screen, as Textual builds
it), and when the key comes back to the app looks its ordinary bindings up in that chain. So
each key acts where it was typed, whatever the keys after it did to the focus.
"""

from __future__ import annotations

from collections import deque
from typing import Any

from textual import events
from textual._dispatch_key import dispatch_key
from textual.app import App
from textual.binding import BindingsMap
from textual.dom import DOMNode

#: keys remembered as handed on: a key a widget takes for itself never comes back, and the
#: oldest ones go (a key climbs back within a few turns of the loop, long before this many
#: others have come)
REMEMBERED = 64

Chain = list[tuple[DOMNode, BindingsMap]]


class DeliveredKeys(App[Any]):
    """An app that looks a key's ordinary bindings up where the key was delivered."""

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        self._delivered_chains: deque[tuple[events.Key, Chain]] = deque(maxlen=REMEMBERED)

    async def on_event(self, event: events.Event) -> None:
        if isinstance(event, events.Key) and not event.is_forwarded and self.screen_stack:
            # what Textual will look the key up in, were the focus still where it is now
            self._delivered_chains.append((event, self.screen._modal_binding_chain))
        await super().on_event(event)

    def delivered_chain(self, event: events.Key) -> Chain | None:
        """The binding chain ``event`` was handed on with (None: not one remembered), now
        forgotten."""
        chains = self._delivered_chains
        for index, (key, chain) in enumerate(chains):
            if key is event:
                del chains[index]
                return chain
        return None

    async def _on_key(self, event: events.Key) -> None:
        chain = self.delivered_chain(event)
        if chain is None:
            return  # Textual's own lookup (App._on_key) runs next
        event.prevent_default()  # and not Textual's: it would look the key up again
        for namespace, bindings in chain:
            if namespace is not self and not namespace.is_attached:
                continue  # a dialog closed meanwhile: its widgets' bindings are gone with it
            for binding in bindings.key_to_bindings.get(event.key, ()):
                if not binding.priority and await self.run_action(binding.action, namespace):
                    return
        await dispatch_key(self, event)
