"""Waiting for something to happen, as the tests do instead of sleeping for a while.

A test waits for the condition it needs and goes on the moment it holds. The deadline only
bounds a failure: it is generous, so that a test passes on a machine busy with other work
(where a step may take many times longer than alone) and fails with a clear message when the
condition never comes.
"""

from __future__ import annotations

import asyncio
import time
from collections.abc import Callable
from typing import TypeVar

T = TypeVar("T")

#: how long a test waits, at most, for something that comes at once on a quiet machine
DEADLINE = 20.0


async def until(
    check: Callable[[], T],
    what: str = "the condition",
    timeout: float = DEADLINE,
    every: float = 0.005,
) -> T:
    """Wait on the running loop until ``check()`` is true, asking every ``every`` seconds;
    its value."""
    loop = asyncio.get_running_loop()
    deadline = loop.time() + timeout
    while not (value := check()):
        if loop.time() >= deadline:
            raise AssertionError(f"{what}: not so after {timeout:g} s")
        await asyncio.sleep(every)
    return value


def wait_until(
    check: Callable[[], T],
    what: str = "the condition",
    timeout: float = DEADLINE,
    every: float = 0.005,
) -> T:
    """Wait in this thread (no loop) until ``check()`` is true, asking every ``every``
    seconds; its value."""
    deadline = time.monotonic() + timeout
    while not (value := check()):
        if time.monotonic() >= deadline:
            raise AssertionError(f"{what}: not so after {timeout:g} s")
        time.sleep(every)
    return value
