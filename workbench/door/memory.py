"""The server process's own memory, watched: past its ceiling the server takes no new
connections, channels or sessions (the live ones go on) until it is below it again.

Every student's connections live in this one process, so memory it cannot get fails whatever
asks next, a live session as well as an attack. Refusing new work a good way before that keeps
the memory for the sessions already in. The resident size is read from ``/proc/self/statm``
(Linux) at most every :data:`EVERY` seconds, so a flood of requests costs one read per period;
where there is no such file the server is not watched.
"""

from __future__ import annotations

import os
import time
from collections.abc import Callable
from dataclasses import dataclass, field

#: seconds a reading is used before the next
EVERY = 0.25
#: what a client refused for want of memory reads
SHORT_OF_MEMORY = "The lab server is short of memory; try again in a few minutes."


def resident_bytes() -> int:
    """This process's resident memory in bytes; 0 where it cannot be read."""
    try:
        with open("/proc/self/statm", "rb") as statm:
            pages = int(statm.read().split()[1])
    except (OSError, ValueError, IndexError):
        return 0
    return pages * os.sysconf("SC_PAGE_SIZE")


@dataclass
class MemoryWatch:
    """Whether the server is past ``ceiling`` MiB (0: never)."""

    ceiling: int
    read: Callable[[], int] = resident_bytes
    _checked: float = field(default=-1e9, init=False)
    _short: bool = field(default=False, init=False)
    last: int = field(default=0, init=False)

    def short(self) -> bool:
        if not self.ceiling:
            return False
        now = time.monotonic()
        if now - self._checked >= EVERY:
            self._checked = now
            self.last = self.read()
            self._short = self.last > self.ceiling * 1024 * 1024
        return self._short

    def refresh(self) -> None:
        """Read again at the next question (after the ceiling or the reading changed)."""
        self._checked = -1e9
