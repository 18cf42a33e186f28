"""Keys that arrive together are handled one after the other, each as it would be alone.

Textual takes a key from the app's queue, runs its priority bindings at once (the app's tab and
shift+tab, so that characters typed after a tab go into the next field), and otherwise hands it
to the focused widget. The key then climbs from that widget to the app, each widget taking it
in its own turn, and its ordinary bindings (a check box's space, a button's enter) run only
when it reaches the app, looked up from the widget focused *then*. Meanwhile the app has taken
the next keys: over SSH a typist's keys come in one packet, so a space for the override box and
a shift+tab right after it arrived together, the shift+tab moved the focus first, and the space
was looked up from the note field and lost; an enter typed next in the note field submitted the
dialog before the box was ticked.

:class:`OrderedKeys` hands a key on only when the one before it has gone its whole way: a small
message follows each key handed to a widget, up the same path (a key a widget takes for itself
stops there; the message goes on), and when it reaches the app the next key waiting is handed
on. So every key acts where the focus is when its turn comes, after everything the keys typed
before it did. Keys typed one at a time never wait: one key's way takes a few turns of the
loop. A key that would wait longer than :data:`LONGEST_WAIT` (its widget removed on the way)
is not waited for.
"""

from __future__ import annotations

from collections import deque
from time import monotonic
from typing import Any

from textual import events
from textual.app import App
from textual.message import Message
from textual.timer import Timer

#: seconds a key waits at most for the one before it to go its way
LONGEST_WAIT = 0.5


class OrderedKeys(App[Any]):
    """An app that handles the keys typed together one after the other (see the module)."""

    class KeyWent(Message):
        """Follows a key from the widget it was handed to, up to the app: the key has gone
        its way."""

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        #: keys that came while another was on its way, in the order typed
        self.keys_waiting: deque[events.Key] = deque()
        #: when the key on its way was handed on (None: no key is on its way)
        self.key_sent_at: float | None = None
        self._key_wait: Timer | None = None

    @property
    def keys_on_their_way(self) -> bool:
        """Whether a key is going its way or waiting for its turn (a key sent longer than
        :data:`LONGEST_WAIT` ago is not waited for, as :meth:`on_event` does not)."""
        sent = self.key_sent_at
        return bool(self.keys_waiting) or (sent is not None and monotonic() - sent < LONGEST_WAIT)

    async def on_event(self, event: events.Event) -> None:
        if isinstance(event, events.Key) and not event.is_forwarded:
            sent = self.key_sent_at
            if self.keys_waiting or (sent is not None and monotonic() - sent < LONGEST_WAIT):
                self.keys_waiting.append(event)
                self._wait_at_most()
                return
            self.key_sent_at = None
            await self._hand_on(event)
            return
        await super().on_event(event)

    async def _hand_on(self, key: events.Key) -> None:
        """Handle ``key`` as Textual does; when it goes to a widget, send the follower after
        it."""
        target = (self.focused or self.screen) if self.screen_stack else None
        await super().on_event(key)
        if key.is_forwarded and target is not None and target.post_message(self.KeyWent()):
            self.key_sent_at = monotonic()

    async def _next_keys(self) -> None:
        """Hand on the keys waiting, one after the other, until one goes to a widget."""
        while self.keys_waiting and self.key_sent_at is None:
            await self._hand_on(self.keys_waiting.popleft())
        self._wait_at_most()

    def _wait_at_most(self) -> None:
        """A timer for keys waiting (none when none wait)."""
        if self.keys_waiting and self._key_wait is None:
            self._key_wait = self.set_timer(LONGEST_WAIT, self._stop_waiting)
        elif not self.keys_waiting and self._key_wait is not None:
            self._key_wait.stop()
            self._key_wait = None

    async def on_ordered_keys_key_went(self, message: KeyWent) -> None:
        message.stop()
        self.key_sent_at = None
        await self._next_keys()

    async def _stop_waiting(self) -> None:
        """Keys have waited a while: when the key on its way has been on it longer than
        :data:`LONGEST_WAIT`, the keys waiting go on without it."""
        self._key_wait = None
        sent = self.key_sent_at
        if sent is not None and monotonic() - sent < LONGEST_WAIT:
            left = LONGEST_WAIT - (monotonic() - sent)
            self._key_wait = self.set_timer(left, self._stop_waiting)
            return
        self.key_sent_at = None
        await self._next_keys()
