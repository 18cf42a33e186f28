"""VIPLE program speed: a headless program run against the FSM engine, on the bundled web maze.

Runs programs/right-wall.viple (Robot Drive, distance and touch events, Timers) and the
built-in right-wall FSM for the same simulated time on mazes/web.txt, without stopping at the
exit, and prints simulated seconds per wall second for each, the interpreter's activity count,
and the program's speed as a share of the FSM's. Target: the program >= 500x real time.
"""

from __future__ import annotations

import time
from pathlib import Path

from workbench.control.headless import AlgorithmPilot, RunSpec, prepare
from workbench.program.interp import ProgramController
from workbench.program.pilot import ProgramPilot

ROOT = Path(__file__).resolve().parents[1]
MAZE = str(ROOT / "mazes" / "web.txt")
PROGRAM = str(ROOT / "programs" / "right-wall.viple")
SECONDS = 600.0
REPEATS = 3


def timed(session) -> float:
    best = float("inf")
    for _ in range(REPEATS):
        session.reset()
        t0 = time.perf_counter()
        session.run(SECONDS, stop_at_exit=False)
        best = min(best, time.perf_counter() - t0)
    return SECONDS / best


def main() -> None:
    fsm = timed(prepare(RunSpec(MAZE, AlgorithmPilot("right-wall"), profile="web")).session)
    ready = prepare(RunSpec(MAZE, ProgramPilot(PROGRAM), profile="web"))
    program = timed(ready.session)
    controller = ready.driving.controller
    assert isinstance(controller, ProgramController)
    print(f"maze {Path(MAZE).name}, {SECONDS:g} simulated s, best of {REPEATS}")
    print(f"  FSM right-wall          {fsm:8.0f}x real time")
    print(
        f"  program right-wall.viple {program:7.0f}x real time "
        f"({controller.steps:,} activities run in the last pass)"
    )
    print(f"  program / FSM           {program / fsm:8.2f}")
    print(f"  target: program >= 500x real time: {'met' if program >= 500 else 'NOT met'}")


if __name__ == "__main__":
    main()
