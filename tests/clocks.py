"""A clock the test moves by hand, for code that takes a clock (a function of no arguments
saying what time it is): ``now`` is what it says, set or advanced by the test, never the
machine's time."""

from __future__ import annotations

from datetime import datetime, timedelta


class Clock:
    """Says ``now``: seconds (from 0 unless told) or, started at a datetime, a datetime."""

    def __init__(self, start: float | datetime = 0.0) -> None:
        self.now = start

    def __call__(self) -> float | datetime:
        return self.now

    def advance(self, seconds: float) -> None:
        if isinstance(self.now, datetime):
            self.now += timedelta(seconds=seconds)
        else:
            self.now += seconds
