"""A screen that draws a change in the wake that made it, not at Textual's next frame tick.

Textual draws a screen's changes from a timer: once a change is made, the screen waits for the
next tick of its 60-a-second update timer, a wake of the process of its own, and draws then.
For a served session that is a second wait for a core after the one that brought the key, and
on a busy server each wait for a core is the largest part of a key's way to the screen.

:class:`PromptFrames` draws at once, when the screen's messages are done (Textual's idle
moment), as long as the last frame is at least one frame period back; a change sooner than
that waits for the timer as before, so the frame rate stays at most Textual's.
"""

from __future__ import annotations

from time import monotonic

from textual import events
from textual.screen import UPDATE_PERIOD, Screen


class PromptFrames(Screen):
    """A screen that draws its changes as soon as they are made (see the module)."""

    _frame_at = 0.0

    async def _on_idle(self, event: events.Idle) -> None:
        if (
            self.is_current
            and not self.app._batch_count
            and (self._dirty_widgets or self._repaint_required)
            and not (self._layout_required or self._scroll_required or self._recompose_required)
            and monotonic() - self._frame_at >= UPDATE_PERIOD
        ):
            event.prevent_default()
            self._on_timer_update()
            return
        await super()._on_idle(event)

    def _on_timer_update(self) -> None:
        self._frame_at = monotonic()
        super()._on_timer_update()
