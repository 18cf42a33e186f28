"""The app's clock: steady ticks, a new rate at once, a tick at once when woken, ticks brought
by keys (one wake for both) but never faster than the clock's rate, no bunched catch-up ticks
after a busy loop, and an error that stops it and reaches the app.

Run on a loop whose time the test moves (the clock only asks a loop for the time and to call
it at a time), and once on a real loop."""

from __future__ import annotations

import asyncio
import heapq
import itertools

import pytest

from tests.waiting import until
from workbench.tui.serving.loop_clock import LoopClock


class Handle:
    def __init__(self) -> None:
        self.cancelled = False

    def cancel(self) -> None:
        self.cancelled = True


class SteppedLoop:
    """A loop's clock and its timed calls, moved on by the test."""

    def __init__(self) -> None:
        self.now = 0.0
        self._calls: list[tuple[float, int, Handle, object]] = []
        self._order = itertools.count()

    def time(self) -> float:
        return self.now

    def call_at(self, when: float, callback) -> Handle:
        handle = Handle()
        heapq.heappush(self._calls, (when, next(self._order), handle, callback))
        return handle

    def run_until(self, end: float, busy_until: float = -1.0) -> None:
        """Run the calls due up to ``end``; until ``busy_until`` the loop is held (calls due
        then run when it is free)."""
        while self._calls and self._calls[0][0] <= end:
            when, _, handle, callback = heapq.heappop(self._calls)
            if handle.cancelled:
                continue
            self.now = max(self.now, when, busy_until if when < busy_until else when)
            callback()
        self.now = end


def clock_on(loop: SteppedLoop, period: float) -> tuple[LoopClock, list[float]]:
    ticks: list[float] = []
    clock = LoopClock(lambda: ticks.append(loop.now), period, pytest.fail, loop=loop)  # type: ignore[arg-type]
    return clock, ticks


def test_it_ticks_at_its_rate_without_drift_and_slows_down_from_now():
    loop = SteppedLoop()
    clock, ticks = clock_on(loop, 0.05)
    loop.run_until(0.26)
    assert ticks == pytest.approx([0.05, 0.10, 0.15, 0.20, 0.25])
    clock.set_period(2.0)  # at rest: the next tick one rest period from now
    loop.run_until(4.5)
    assert ticks[5:] == pytest.approx([2.26, 4.26])
    clock.stop()
    loop.run_until(10.0)
    assert len(ticks) == 7 and not clock.running


def test_woken_at_once_it_ticks_now_and_then_at_its_rate():
    loop = SteppedLoop()
    clock, ticks = clock_on(loop, 0.05)
    clock.set_period(2.0)
    loop.run_until(3.33)
    assert ticks == pytest.approx([2.0])
    clock.set_period(0.05, at_once=True)  # a VIPLE command: drawn at once
    loop.run_until(3.5)
    assert ticks[1:] == pytest.approx([3.33, 3.38, 3.43, 3.48])


def test_a_busy_loop_gets_one_late_tick_not_a_burst():
    loop = SteppedLoop()
    _, ticks = clock_on(loop, 0.05)
    loop.run_until(0.99, busy_until=0.52)  # ten ticks fall due while the loop is held
    assert ticks[:3] == pytest.approx([0.52, 0.57, 0.62])  # one late tick, then the rate
    assert len(ticks) == 10


def keys_at(loop: SteppedLoop, clock: LoopClock, times: list[float]) -> list[bool]:
    """Nudge the clock at each time, as keys do; whether each nudge ticked."""
    ticked = []
    for at in times:
        loop.run_until(at)
        ticked.append(clock.nudge())
    return ticked


def test_keys_at_the_tick_rate_bring_the_ticks_and_the_timer_stays_asleep():
    loop = SteppedLoop()
    clock, ticks = clock_on(loop, 0.05)
    # a student's keys twenty times a second, a little uneven, out of step with the clock
    keys = [0.013 + 0.05 * i + (0.004 if i % 3 else -0.004) for i in range(40)]
    ticked = keys_at(loop, clock, keys)
    assert ticked[0] is False  # 9 ms after the clock started
    assert all(ticked[1:])  # from the second key on, every key brings a tick
    assert ticks == pytest.approx(keys[1:])  # and no tick comes without a key: one wake each
    loop.run_until(keys[-1] + 0.2)  # the keys stop: the clock goes on on its own
    assert ticks[39:] == pytest.approx([keys[-1] + 0.06, keys[-1] + 0.11, keys[-1] + 0.16])


def test_faster_keys_tick_at_most_a_third_faster_than_the_clock():
    loop = SteppedLoop()
    clock, ticks = clock_on(loop, 0.05)
    keys = [0.01 * i for i in range(1, 101)]  # a hundred keys a second for a second
    keys_at(loop, clock, keys)
    gaps = [b - a for a, b in itertools.pairwise(ticks)]
    assert min(gaps) >= 0.75 * 0.05 - 1e-9 and 18 <= len(ticks) <= 27


def test_a_key_just_after_a_tick_puts_the_next_tick_off_but_ticks_no_more():
    loop = SteppedLoop()
    clock, ticks = clock_on(loop, 0.05)
    loop.run_until(0.06)
    assert keys_at(loop, clock, [0.07]) == [False]  # 20 ms after the tick at 0.05
    loop.run_until(0.2)  # no more keys: the next tick a period and the slack after the key
    assert ticks == pytest.approx([0.05, 0.13, 0.18])


def test_an_error_stops_the_clock_and_reaches_the_app():
    loop = SteppedLoop()
    errors: list[Exception] = []

    def tick() -> None:
        raise RuntimeError("a broken tick")

    clock = LoopClock(tick, 0.01, errors.append, loop=loop)  # type: ignore[arg-type]
    loop.run_until(1.0)
    assert [str(e) for e in errors] == ["a broken tick"] and not clock.running


def test_a_period_must_be_positive():
    loop = SteppedLoop()
    with pytest.raises(ValueError, match="positive"):
        clock_on(loop, 0)
    clock, _ = clock_on(loop, 1.0)
    with pytest.raises(ValueError, match="positive"):
        clock.set_period(-1.0)


def test_it_ticks_on_a_real_loop_until_stopped():
    async def go() -> None:
        ticks: list[float] = []
        clock = LoopClock(lambda: ticks.append(0.0), 0.01, pytest.fail)
        await until(lambda: len(ticks) >= 5, "five ticks")
        clock.stop()
        assert not clock.running

    asyncio.run(go())
