"""VIPLE program speed: a headless program run beside the FSM of the same algorithm, on the
bundled web maze, and the real-time factor of a whole ``workbench viple run`` process.

Each pair runs for the same simulated time on mazes/web.txt without stopping at the exit, the
FSM and the program taking turns (best of REPEATS each, so a busy machine slows both alike):

- web-wall-following: programs/web-wall-following.viple and the built-in FSM of the same name
  (the same sensors, wheel powers, timed spins and 20 ms correction spins);
- right-wall: programs/right-wall.viple (Robot Drive, distance and touch, Timers) and the
  built-in right-wall FSM (Turn by Degree and a front distance sensor: not the same robot, so
  the two trajectories, and the physics they cost, differ).

Prints simulated seconds per wall second for each, the interpreter's activity count, and the
program's speed as a share of the FSM's, with a target line for each pair (>= 0.85 for
web-wall-following, the same algorithm; >= 0.70 for right-wall, whose robot differs). Then runs
``workbench viple run`` as its own process for 600 simulated s (a copy of the maze without its
exit, so the run is not cut short) and prints its real-time factor, start-up included.
"""

from __future__ import annotations

import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from workbench.control.headless import AlgorithmPilot, RunSpec, prepare
from workbench.program.interp import ProgramController
from workbench.program.pilot import ProgramPilot
from workbench.sim.session import Session

ROOT = Path(__file__).resolve().parents[1]
MAZE = str(ROOT / "mazes" / "web.txt")
PAIRS = (
    ("web-wall-following", str(ROOT / "programs" / "web-wall-following.viple")),
    ("right-wall", str(ROOT / "programs" / "right-wall.viple")),
)
#: the share of its FSM's speed each program should reach
TARGETS = {"web-wall-following": 0.85, "right-wall": 0.70}
SECONDS = 600.0
REPEATS = 5


def once(session: Session) -> float:
    session.reset()
    t0 = time.perf_counter()
    session.run(SECONDS, stop_at_exit=False)
    return time.perf_counter() - t0


def pair(algorithm: str, program: str) -> tuple[float, float, int]:
    """Simulated seconds per wall second of the FSM and of the program; activities run."""
    fsm = prepare(RunSpec(MAZE, AlgorithmPilot(algorithm), profile="web"))
    ready = prepare(RunSpec(MAZE, ProgramPilot(program), profile="web"))
    best_fsm = best_program = float("inf")
    for _ in range(REPEATS):
        best_fsm = min(best_fsm, once(fsm.session))
        best_program = min(best_program, once(ready.session))
    controller = ready.driving.controller
    assert isinstance(controller, ProgramController)
    return SECONDS / best_fsm, SECONDS / best_program, controller.steps


def whole_process(program: str) -> tuple[float, float]:
    """Wall and CPU seconds of ``workbench viple run`` for SECONDS simulated, as a user starts
    it (on a busy machine the CPU time says more)."""
    text = Path(MAZE).read_text(encoding="utf-8").replace("E", "#")
    with tempfile.TemporaryDirectory() as folder:
        maze = Path(folder) / "web-no-exit.txt"
        maze.write_text(text, encoding="utf-8")
        command = [sys.executable, "-m", "workbench", "viple", "run", program, "--maze"]
        command += [str(maze), "--max-time", f"{SECONDS:g}", "--json"]
        before = resource.getrusage(resource.RUSAGE_CHILDREN)
        t0 = time.perf_counter()
        done = subprocess.run(command, capture_output=True, text=True, check=False)
        wall = time.perf_counter() - t0
        after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if done.returncode not in (0, 1):
        raise SystemExit(f"workbench viple run failed:\n{done.stderr}")
    cpu = (after.ru_utime + after.ru_stime) - (before.ru_utime + before.ru_stime)
    return wall, cpu


def main() -> None:
    print(f"maze {Path(MAZE).name}, {SECONDS:g} simulated s, best of {REPEATS}, taking turns")
    shares = {}
    for algorithm, program in PAIRS:
        fsm, prog, steps = pair(algorithm, program)
        shares[algorithm] = prog / fsm
        print(f"  {algorithm}")
        print(f"    FSM          {fsm:7.0f}x real time")
        print(f"    program      {prog:7.0f}x real time ({steps:,} activities run)")
        print(f"    program/FSM  {prog / fsm:7.2f}")
    for algorithm, target in TARGETS.items():
        met = shares[algorithm] >= target
        print(
            f"  target {algorithm}: program >= {target:.2f} of its FSM: "
            f"{'met' if met else 'NOT met'} ({shares[algorithm]:.2f})"
        )
    for _, program in PAIRS:
        wall, cpu = whole_process(program)
        print(
            f"workbench viple run {Path(program).name}, whole process, {SECONDS:g} simulated s: "
            f"{wall:.2f} s wall ({SECONDS / wall:.0f}x real time), "
            f"{cpu:.2f} s CPU ({SECONDS / cpu:.0f}x)"
        )


if __name__ == "__main__":
    main()
