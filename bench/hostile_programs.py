"""Hostile VIPLE programs under ``workbench viple check`` and ``viple run``: how long each takes
to end and the most memory its process held.

Writes the programs of ``tests/program/hostile.py`` to a temporary folder, then runs each in a
process of its own: the files made to be slow to check under ``viple check``, the programs that
grow or spin under ``viple run --max-time S --record FILE`` on the bundled web maze. Prints, for
each, the wall time, the peak resident memory of its process, the run record's size, and the
first line that says how it ended. Figures vary from run to run on a shared machine.

Usage: ``python bench/hostile_programs.py [--max-time 60] [--only merge_spin]``.
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from tests.program import hostile  # noqa: E402

CHECKED = (
    "long_robot_name",
    "long_comment",
    "while_lattice",
    "many_whiles",
    "many_attributes",
    "many_elements",
)
RUN = ("join_nesting", "join_doubling", "number_doubling", "record_flood", "merge_spin")
#: words in the output that say how the program ended, most telling first
TELLING = ("STOPPED at", "run record ", "too tangled", "errors:", ": ", "ok (")


def measure(args: list[str], timeout: float) -> tuple[float, float, str]:
    """Wall seconds, peak resident MB of the process (its own, from wait4), and its output."""
    started = time.perf_counter()
    with tempfile.TemporaryFile("w+") as out:
        child = subprocess.Popen(args, stdout=out, stderr=subprocess.STDOUT)
        while True:
            pid, status, usage = os.wait4(child.pid, os.WNOHANG)
            if pid:
                break
            if time.perf_counter() - started > timeout:
                child.kill()
                pid, status, usage = os.wait4(child.pid, 0)
                out.write(f"\ndid not end within {timeout:g} s")
                break
            time.sleep(0.05)
        child.returncode = os.waitstatus_to_exitcode(status)
        wall = time.perf_counter() - started
        out.seek(0)
        return wall, usage.ru_maxrss / 1024, out.read()


def telling(out: str) -> str:
    lines = out.splitlines()
    for word in TELLING:
        for line in lines:
            if word in line:
                return line.strip()[:150]
    return (lines[-1] if lines else "").strip()[:150]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n", 1)[0])
    parser.add_argument("--max-time", type=float, default=60.0, help="simulated seconds a run")
    parser.add_argument("--timeout", type=float, default=300.0, help="wall seconds a process")
    parser.add_argument("--only", action="append", default=[], metavar="NAME")
    options = parser.parse_args()
    workbench = [sys.executable, "-m", "workbench"]
    maze = str(ROOT / "mazes" / "web.txt")
    print(f"{'program':18} {'command':6} {'wall s':>7} {'peak MB':>8} {'record':>9}  ended")
    with tempfile.TemporaryDirectory() as folder:
        for name in (*CHECKED, *RUN):
            if options.only and name not in options.only:
                continue
            path = os.path.join(folder, f"{name}.viple")
            Path(path).write_text(getattr(hostile, name)())
            record = os.path.join(folder, f"{name}.jsonl")
            if name in CHECKED:
                command = [*workbench, "viple", "check", path]
            else:
                command = [*workbench, "viple", "run", path, "--maze", maze]
                command += ["--max-time", f"{options.max_time:g}", "--record", record]
            wall, peak, out = measure(command, options.timeout)
            size = os.path.getsize(record) if os.path.exists(record) else 0
            kind = command[4]
            print(f"{name:18} {kind:6} {wall:7.2f} {peak:8.0f} {size:9,d}  {telling(out)}")


if __name__ == "__main__":
    main()
