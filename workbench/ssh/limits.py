"""The server's limits: sessions per user and in all, and slowing down failed logins."""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass


@dataclass(frozen=True)
class SessionLimits:
    per_user: int = 2
    total: int = 60
    idle_timeout: float = 7200.0

    def refusal(self, user_sessions: int, all_sessions: int) -> str | None:
        """The message for a user who would open one more session, or None when it may."""
        if all_sessions >= self.total:
            many = "session" if self.total == 1 else "sessions"
            return f"The lab server is full ({self.total} {many}); try again in a few minutes."
        if user_sessions >= self.per_user:
            many = "session" if self.per_user == 1 else "sessions"
            return (
                f"You already have {self.per_user} workbench {many} open, the most one "
                "user may have; quit one (ctrl+q) and try again."
            )
        return None


def describe_duration(seconds: float) -> str:
    """``7200`` as ``"2 h"``, ``90`` as ``"90 s"``: for the idle-timeout message."""
    if seconds >= 3600 and seconds % 3600 == 0:
        return f"{int(seconds // 3600)} h"
    if seconds >= 60 and seconds % 60 == 0:
        return f"{int(seconds // 60)} min"
    return f"{seconds:g} s"


class FailureDelay:
    """How long to wait before answering a login attempt from an address.

    Nothing after no failures; then ``first`` seconds, doubled per failure up to ``most``.
    A success, or ``quiet`` seconds without a failure, forgets the address's failures.
    """

    def __init__(
        self,
        first: float = 0.5,
        most: float = 8.0,
        quiet: float = 600.0,
        clock: Callable[[], float] = time.monotonic,
    ) -> None:
        self.first, self.most, self.quiet = first, most, quiet
        self._clock = clock
        self._failures: dict[str, tuple[int, float]] = {}

    def failures(self, address: str) -> int:
        count, last = self._failures.get(address, (0, 0.0))
        if count and self._clock() - last >= self.quiet:
            del self._failures[address]
            return 0
        return count

    def delay(self, address: str) -> float:
        count = self.failures(address)
        if count == 0:
            return 0.0
        return min(self.first * 2 ** (count - 1), self.most)

    def failed(self, address: str) -> None:
        now = self._clock()
        count = self.failures(address)
        self._failures[address] = (count + 1, now)
        if len(self._failures) > 10_000:  # forget the quiet addresses
            for key, (_, last) in list(self._failures.items()):
                if now - last >= self.quiet:
                    del self._failures[key]

    def succeeded(self, address: str) -> None:
        self._failures.pop(address, None)
