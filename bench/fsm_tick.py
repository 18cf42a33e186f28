"""The cost of an FSM control tick that changes nothing.

A wall-following algorithm on the Web Simulator profile, its front clear and its wall at the
set distance, ticks TICKS times without a transition (best of three). It prints the
microseconds per tick (target < 50). The tests check only what such a tick does
(tests/unit/test_fsm.py).
"""

from __future__ import annotations

import time

from workbench.fsm.algorithms import load_algorithm
from workbench.fsm.machine import FsmController

DT = 1 / 60
TICKS = 20_000


def fsm_tick() -> float:
    """Seconds per FSM tick that changes nothing (best of three)."""
    ctl = FsmController(load_algorithm("self-adjusting-wall"), {}, "web")
    ctl.start(0)
    readings = {"front": 300.0, "right": 25.0}
    none: frozenset[str] = frozenset()
    ctl.tick(DT, readings, none)
    best = float("inf")
    for _ in range(3):
        begin = time.perf_counter()
        for i in range(TICKS):
            ctl.tick(i * DT, readings, none)
        best = min(best, (time.perf_counter() - begin) / TICKS)
    assert ctl.state == "Forward", ctl.state
    return best


def main() -> None:
    print(f"FSM tick without a transition: {fsm_tick() * 1e6:7.1f} us   (target < 50 us)")


if __name__ == "__main__":
    main()
