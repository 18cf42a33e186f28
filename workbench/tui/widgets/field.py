"""A text field whose editing keys act in the order they were typed.

Textual's ``Input`` inserts a printable key as soon as it arrives but runs its editing keys
(backspace, arrows, ctrl+u...) as bindings once the key has bubbled up to the app. Over SSH
a typist's keys arrive together, so "backspace 5" became "5, then backspace" and the 5 was
lost. :class:`Field` runs its own editing bindings when the key reaches it, in order.

Its cursor does not blink: a blinking cursor redraws the field twice a second, which a served
student sitting at the names dialog pays for in the app and again in the SSH server.
"""

from __future__ import annotations

from textual import events
from textual.binding import Binding
from textual.message import Message
from textual.widgets import Input

from ..textual_private import KeyFirstInput

#: every key Input binds, and the action it runs
_EDITING = {
    key.strip(): binding.action
    for binding in Input.BINDINGS
    if isinstance(binding, Binding)
    for key in binding.key.split(",")
}


class Field(KeyFirstInput):
    """``Input`` with typed-ahead editing keys kept in order and a steady cursor.

    With a ``max_length``, text typed or pasted past it is cut to fit (Textual's ``Input``
    would refuse all of it) and :class:`Field.Capped` tells the screen, to say so.
    """

    class Capped(Message):
        """Text did not fit in the field: only its first ``limit`` characters are kept."""

        def __init__(self, field: Field, limit: int) -> None:
            super().__init__()
            self.field = field
            self.limit = limit

        @property
        def control(self) -> Field:
            return self.field

    def __init__(self, *args: object, **kwargs: object) -> None:
        super().__init__(*args, **kwargs)  # type: ignore[arg-type]
        self.set_reactive(Input.cursor_blink, False)

    def replace(self, text: str, start: int, end: int) -> None:
        limit = self.max_length
        if limit:
            value = self.value
            low, high = sorted((max(0, start), min(len(value), end)))
            room = max(0, limit - (len(value) - (high - low)))
            if len(text) > room:
                super().replace(text[:room], start, end)
                self.post_message(self.Capped(self, limit))
                return
        super().replace(text, start, end)

    async def take_key(self, event: events.Key) -> bool:
        action = _EDITING.get(event.key)
        if action is None:
            return False
        event.stop()
        event.prevent_default()
        await self.run_action(action)
        return True
