"""The app's clock: steady ticks on the loop, a new rate at once, no bunched catch-up ticks
after a busy loop, and an error that stops it and reaches the app."""

from __future__ import annotations

import asyncio
import time

import pytest

from workbench.tui.clock import LoopClock


def test_it_ticks_at_its_rate_and_changes_rate_at_once():
    async def go() -> tuple[list[float], list[float]]:
        fast: list[float] = []
        slow: list[float] = []
        ticks = fast
        clock = LoopClock(lambda: ticks.append(time.monotonic()), 0.02, pytest.fail)
        await asyncio.sleep(0.5)
        ticks = slow
        clock.set_period(0.2)
        await asyncio.sleep(0.5)
        clock.stop()
        assert not clock.running
        await asyncio.sleep(0.3)
        return fast, slow

    fast, slow = asyncio.run(go())
    assert 15 <= len(fast) <= 26  # 25 at 50 Hz, less when the machine is busy
    assert 1 <= len(slow) <= 3  # 2 at 5 Hz, none after the stop


def test_a_busy_loop_gets_one_late_tick_not_a_burst():
    async def go() -> list[float]:
        ticks: list[float] = []
        clock = LoopClock(lambda: ticks.append(time.monotonic()), 0.05, pytest.fail)
        await asyncio.sleep(0.12)
        time.sleep(0.5)  # the loop is held: ten ticks fall due
        blocked = len(ticks)
        await asyncio.sleep(0.12)
        clock.stop()
        return ticks[blocked:]

    after = asyncio.run(go())
    assert 1 <= len(after) <= 3  # one late tick, then the rate again
    if len(after) > 1:
        assert after[1] - after[0] >= 0.04


def test_an_error_stops_the_clock_and_reaches_the_app():
    async def go() -> tuple[list[Exception], LoopClock]:
        errors: list[Exception] = []

        def tick() -> None:
            raise RuntimeError("a broken tick")

        clock = LoopClock(tick, 0.01, errors.append)
        await asyncio.sleep(0.1)
        return errors, clock

    errors, clock = asyncio.run(go())
    assert [str(e) for e in errors] == ["a broken tick"] and not clock.running


def test_a_period_must_be_positive():
    async def go() -> None:
        with pytest.raises(ValueError, match="positive"):
            LoopClock(lambda: None, 0, pytest.fail)
        clock = LoopClock(lambda: None, 1.0, pytest.fail)
        with pytest.raises(ValueError, match="positive"):
            clock.set_period(-1.0)
        clock.stop()

    asyncio.run(go())
