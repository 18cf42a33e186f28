"""The app's clock: a function called at a steady rate straight from the event loop.

The simulation ticks twenty times a second for as long as a student drives. A Textual timer
would run each tick as a task waking from a sleep (a future, a timer handle, a task step and
the timer's own checks); this clock is one timer handle per tick on the app's loop, in the
app's context, so each tick costs the call and little else.

The ticks fall on a grid of times one period apart from the clock's start. A tick that falls
behind (the loop was busy) runs as soon as it can and the next one is the grid's next time:
ticks are never bunched up to catch up (the simulation is handed the real time that passed,
whatever it is).
"""

from __future__ import annotations

import asyncio
from collections.abc import Callable


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
        self._start = self._loop.time()
        self._due = self._start + period
        self._handle: asyncio.TimerHandle | None = self._loop.call_at(self._due, self._run)

    @property
    def running(self) -> bool:
        return self._handle is not None

    def set_period(self, period: float, at_once: bool = False) -> None:
        """Tick every ``period`` seconds from now on: the next tick one period from now, or
        with ``at_once`` a tick as soon as the loop is free and then on the clock's own grid
        (the times one period apart from its start), as before it slowed down."""
        if period <= 0:
            raise ValueError(f"a clock period must be positive, not {period}")
        changed = period != self.period
        self.period = period
        if self._handle is None or not (changed or at_once):
            return
        self._handle.cancel()
        now = self._loop.time()
        if at_once:  # this tick stands for the grid's last time; the next is its next
            self._due = now - (now - self._start) % period
            self._handle = self._loop.call_at(now, self._run)
        else:
            self._due = now + period
            self._handle = self._loop.call_at(self._due, self._run)

    def stop(self) -> None:
        if self._handle is not None:
            self._handle.cancel()
            self._handle = None

    def _run(self) -> None:
        loop = self._loop
        period = self.period
        now = loop.time()
        due = self._due + period
        if due <= now:  # late: on to the grid's next time
            due = now + period - (now - self._start) % period
        self._due = due
        self._handle = loop.call_at(self._due, self._run)
        try:
            self._tick()
        except Exception as error:  # the app's own error: shown by the app, which then ends
            self.stop()
            self._on_error(error)
