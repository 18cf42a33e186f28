"""How many typed keys a served app takes: a burst of :data:`BURST` at once, then
:data:`RATE` a second; keys past that are dropped, and the student is told how many.

Every typed key is handled on the app's one loop, one after the other (``ordered_keys``), at
about a millisecond each with its redraw, ten on a busy machine: 64 KiB of keys sent at once
froze an app for over a minute, its own student locked out of it. A person types a few keys a
second and a held key repeats some thirty times a second; fifty a second stay well within a
core even at ten milliseconds each. A paste the terminal marks as one (bracketed paste, which
the editor and the dialogs take whole) is one event, never counted here. So the budget bites
only on a flood, or on a long paste into a terminal that sends it as typed keys.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, field

#: keys taken at once, and a second after that
BURST = 256
RATE = 50.0


def dropped_message(count: int) -> str:
    many = "key was" if count == 1 else "keys were"
    return (
        f"{count} typed {many} dropped: they came faster than the workbench takes them "
        f"(at most {BURST} at once, then {RATE:g} a second); paste long text with your "
        "terminal's paste, which comes whole"
    )


@dataclass
class KeyBudget:
    """The keys an app may take now; :meth:`take` spends from it."""

    burst: int = BURST
    rate: float = RATE
    clock: Callable[[], float] = time.monotonic
    _left: float = field(init=False)
    _at: float = field(init=False)
    #: keys dropped and not yet told
    dropped: int = field(default=0, init=False)

    def __post_init__(self) -> None:
        self._left = float(self.burst)
        self._at = self.clock()

    def take(self, count: int) -> int:
        """How many of ``count`` keys may go (the first ones); the rest are counted dropped."""
        now = self.clock()
        self._left = min(float(self.burst), self._left + (now - self._at) * self.rate)
        self._at = now
        allowed = min(count, int(self._left))
        self._left -= allowed
        self.dropped += count - allowed
        return allowed

    def told(self) -> int:
        """The keys dropped since last told, and none left to tell."""
        count, self.dropped = self.dropped, 0
        return count
