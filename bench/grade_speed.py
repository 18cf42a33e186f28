"""Grading speed: a class of 60 programs on 3 mazes, two programs at a time.

The class is made in a temporary folder: 44 right-wall followers that start at once, 10 that
wait for a key and bring their key script (``NAME.keys``), 3 that wait for a key they never
get (they drive nothing until the time limit), 3 damaged files. Each program runs on the web
maze and the two ranking mazes (Web Simulator profile, seed 0) through ``workbench grade``'s
engine, each in a process of its own, and the bench prints programs per minute. Target: the
60 programs x 3 mazes within 60 s on 2 processors.
"""

from __future__ import annotations

import resource
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from tests.program.graded_programs import right_wall  # noqa: E402
from workbench.program.grading import Limits, Plan, grade  # noqa: E402
from workbench.program.submissions import find_submissions  # noqa: E402

MAZES = tuple(str(ROOT / "mazes" / m) for m in ("web.txt", "rank-wall-wins.txt",
                                                 "rank-local-best-wins.txt"))  # fmt: skip
JOBS = 2
TARGET = 60.0


def make_class(folder: Path) -> None:
    for i in range(44):
        right_wall(folder / f"student{i:02d}.viple")
    for i in range(44, 54):
        right_wall(folder / f"student{i:02d}.viple", start_key="a")
        (folder / f"student{i:02d}.keys").write_text(f"a@{0.1 * (i - 43):.1f}\n")
    for i in range(54, 57):
        right_wall(folder / f"student{i:02d}.viple", start_key="a")
    for i in range(57, 60):
        good = (folder / "student00.viple").read_bytes()
        (folder / f"student{i:02d}.viple").write_bytes(good[: 200 * (i - 56)])


def _cpu() -> float:
    """Processor seconds of this process and its children that have ended."""
    own = resource.getrusage(resource.RUSAGE_SELF)
    children = resource.getrusage(resource.RUSAGE_CHILDREN)
    return own.ru_utime + own.ru_stime + children.ru_utime + children.ru_stime


def main() -> None:
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        make_class(folder)
        submissions = find_submissions(folder)
        plan = Plan(str(folder), MAZES, profile="web")
        cpu0 = _cpu()
        t0 = time.perf_counter()
        rows = grade(submissions, plan, jobs=JOBS, limits=Limits())
        took = time.perf_counter() - t0
        cpu = _cpu() - cpu0
    programs = len(submissions)
    out = sum(r.reached_exit for r in rows)
    refused = sum(bool(r.refusal) for r in rows)
    print(f"{programs} programs x {len(MAZES)} mazes = {len(rows)} runs, {JOBS} at a time")
    print(f"  {out} runs reached the exit, {refused} refused")
    print(f"  {took:.1f} s: {programs / took * 60:.0f} programs per minute")
    print(
        f"  {cpu:.1f} processor seconds in all (the grader and the programs' processes): "
        f"{cpu / JOBS:.1f} s on {JOBS} otherwise idle processors"
    )
    met = took <= TARGET
    print(f"  target: {programs} programs x {len(MAZES)} mazes within {TARGET:g} s: "
          f"{'met' if met else 'NOT met'}")  # fmt: skip


if __name__ == "__main__":
    main()
