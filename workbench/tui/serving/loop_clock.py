"""The app's clock: a function called at a steady rate straight from the event loop, and early
when the app is awake anyway.

The simulation ticks twenty times a second for as long as a student drives. A Textual timer
would run each tick as a task waking from a sleep (a future, a timer handle, a task step and
the timer's own checks); this clock is one timer handle per tick on the app's loop, in the
app's context, so each tick costs the call and little else.

Waking a process costs more than most ticks do (a served app that sleeps between ticks and
keys wakes some forty times a second while a student drives, and each wake has the kernel's
and the interpreter's cost of coming back). A key wakes the app anyway, so the app asks the
clock to tick then (:meth:`LoopClock.nudge`): when the last tick is far enough back, the clock
ticks at once, with the key's effect in it; either way its next tick moves a period (and a
little slack) on, so that a student's next key, not the timer, brings it. Keys at the tick rate or
faster then cost one wake each, with the ticks in them; the rate stays the same, the drawing
of a key is not held back for the next tick, and with no keys the clock ticks on its own.

A tick that falls behind (the loop was busy) runs as soon as it can and the next one is a
period after it: ticks are never bunched up to catch up (the simulation is handed the real time
that passed, whatever it is).
"""

from __future__ import annotations

import asyncio
from collections.abc import Callable

#: how much of a period must have passed since the last tick for a nudge to tick
NUDGE_AFTER = 0.75
#: how far past a period after a nudged tick the next one is due (a share of the period), so a
#: key that comes about a period later, a little late, still brings it
NUDGE_SLACK = 0.2


class LoopClock:
    """Calls ``tick`` every ``period`` seconds on the running loop until stopped.

    An exception from ``tick`` goes to ``on_error`` (the app ends with it shown, as it does
    for any error in its own code); the clock then stops.
    """

    def __init__(
        self,
        tick: Callable[[], None],
        period: float,
        on_error: Callable[[Exception], None],
        loop: asyncio.AbstractEventLoop | None = None,
    ) -> None:
        """``loop``: the running loop unless given."""
        if period <= 0:
            raise ValueError(f"a clock period must be positive, not {period}")
        self._tick = tick
        self._on_error = on_error
        self.period = period
        self._loop = loop or asyncio.get_running_loop()
        self._ticked = self._loop.time()
        self._handle: asyncio.TimerHandle | None = None
        self._due = self._ticked
        self._schedule(self._ticked + period)

    @property
    def running(self) -> bool:
        return self._handle is not None

    def set_period(self, period: float, at_once: bool = False) -> None:
        """Tick every ``period`` seconds from now on: the next tick one period from now, or
        with ``at_once`` as soon as the loop is free."""
        if period <= 0:
            raise ValueError(f"a clock period must be positive, not {period}")
        changed = period != self.period
        self.period = period
        if self._handle is not None and (changed or at_once):
            now = self._loop.time()
            self._schedule(now if at_once else now + period)

    def nudge(self) -> bool:
        """The app is awake anyway (a key came): tick now if the last tick is at least
        ``NUDGE_AFTER`` of a period back; the next tick is put a period and ``NUDGE_SLACK`` of
        one from now either way. Returns whether it ticked."""
        if self._handle is None:
            return False
        now = self._loop.time()
        period = self.period
        # the next tick waits for the next key, whether this one ticks or came too soon (then
        # the ticks fall in step with the keys from the next one on)
        self._schedule(now + period * (1.0 + NUDGE_SLACK))
        if now - self._ticked < NUDGE_AFTER * period:
            return False
        self._call(now)
        return True

    def stop(self) -> None:
        if self._handle is not None:
            self._handle.cancel()
            self._handle = None

    def _schedule(self, when: float) -> None:
        if self._handle is not None:
            self._handle.cancel()
        self._due = when
        self._handle = self._loop.call_at(when, self._run)

    def _run(self) -> None:
        now = self._loop.time()
        due = self._due + self.period  # on time: no drift from the loop's latency
        self._schedule(due if due > now else now + self.period)
        self._call(now)

    def _call(self, now: float) -> None:
        self._ticked = now
        try:
            self._tick()
        except Exception as error:  # the app's own error: shown by the app, which then ends
            self.stop()
            self._on_error(error)
