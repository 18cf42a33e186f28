"""Real time for a session: a fixed-step accumulator over wall-clock time.

Front ends (the app, ``workbench serve``) call :meth:`Pacer.advance` with the wall time that has
passed; the pacer runs as many fixed ``dt`` steps as that time (times the speed factor) holds,
carrying the remainder, so the trajectory is the same as a headless run's whatever the frame
rate. Timers that skip ticks do not lose simulated time. Stepping stops at the step on which
the robot gets out of a maze with exits, at every speed and in single steps, as a headless run
does: a run's numbers do not depend on how fast it is shown.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, field

from .session import Session
from .world import EXIT

SPEEDS = (1.0, 2.0, 4.0, 10.0, None)  # None = as fast as the budget allows ("max")


@dataclass
class Pacer:
    session: Session
    speed: float | None = 1.0
    paused: bool = False
    #: at most this much wall time of stepping per call, so a slow frame cannot snowball
    budget: float = 0.05
    #: wall time owed to the simulation beyond this is dropped (after a stall, do not race)
    max_lag: float = 0.25
    clock: Callable[[], float] = field(default=time.perf_counter)
    _debt: float = 0.0

    def advance(self, wall_seconds: float, lag: float | None = None) -> int:
        """Run the steps ``wall_seconds`` of real time call for; returns how many ran.

        ``lag`` overrides :attr:`max_lag` for this call: a front end that ticks seldom on
        purpose (while nothing moves) keeps all the time it owes.
        """
        if self.paused:
            self._debt = 0.0
            return 0
        dt = self.session.world.dt
        step = self.session.step
        out = self._exits()
        if self.speed is None:
            deadline = self.clock() + self.budget
            n = 0
            while True:
                for _ in range(30):
                    n += 1
                    if EXIT in step() and out:
                        return n
                if self.clock() >= deadline:
                    return n
        keep = self.max_lag if lag is None else lag
        self._debt = min(self._debt + wall_seconds * self.speed, keep * self.speed)
        n = int(self._debt / dt + 1e-9)
        self._debt -= n * dt
        deadline = self.clock() + self.budget
        for i in range(n):
            if EXIT in step() and out:
                self._debt = 0.0
                return i + 1
            if (i & 31) == 31 and self.clock() > deadline:
                self._debt = 0.0
                return i + 1
        return n

    def single_step(self, steps: int = 1) -> int:
        """Advance ``steps`` physics steps (for pause + step, and for tests), fewer when the
        robot gets out first; returns how many ran."""
        out = self._exits()
        for i in range(steps):
            if EXIT in self.session.step() and out:
                return i + 1
        return steps

    def _exits(self) -> bool:
        """Whether getting out ends the run: the maze has exits."""
        return bool(self.session.maze.exits)

    def set_speed(self, speed: float | None) -> None:
        """Run at ``speed`` (one of :data:`SPEEDS`) from now on."""
        if speed not in SPEEDS:
            raise ValueError(f"speed {speed} is not one of {SPEEDS}")
        self.speed = speed
        self._debt = 0.0

    def next_speed(self) -> float | None:
        i = SPEEDS.index(self.speed) if self.speed in SPEEDS else 0
        self.speed = SPEEDS[(i + 1) % len(SPEEDS)]
        self._debt = 0.0
        return self.speed
