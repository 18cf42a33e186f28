"""One bench, run on this tree and on an older revision in turn: before and after in one run.

    python bench/before_after.py --rev REV [--rounds 3] BENCH.py [BENCH ARGS...]

Exports revision REV beside this tree (``bench/gitrev.py``), then runs the bench alternately from
the older tree and from this one, ROUNDS times each, with this interpreter and ``PYTHONPATH``
naming the tree that runs, so its ``workbench`` is found before the installed one (in the bench
and in the servers it starts). Each run's output is printed under a heading naming the tree, the
round and the load average just before it; the lines that hold a figure are gathered again at the
end, old and new side by side, so a reader sees every round's figure. Nothing is averaged away.
"""

from __future__ import annotations

import argparse
import os
import re
import subprocess
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
sys.path.insert(0, str(HERE))

from gitrev import export  # noqa: E402

FIGURE = re.compile(r"\d")


def load() -> str:
    one, five, _fifteen = os.getloadavg()
    return f"load {one:.2f} (5 min {five:.2f})"


def run_once(tree: Path, bench: str, args: list[str]) -> tuple[str, float]:
    script = tree / "bench" / bench
    if not script.is_file():
        raise SystemExit(f"{script} does not exist: that revision has no bench of that name")
    start = time.monotonic()
    done = subprocess.run(
        [sys.executable, str(script), *args],
        cwd=tree,
        env={**os.environ, "PYTHONPATH": str(tree)},
        capture_output=True,
        text=True,
        check=False,
    )
    took = time.monotonic() - start
    text = done.stdout + (f"\n[stderr]\n{done.stderr}" if done.returncode else "")
    if done.returncode:
        text += f"\n[exit {done.returncode}]"
    return text, took


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--rev", required=True, help="the older revision (a commit, tag or branch)")
    parser.add_argument("--rounds", type=int, default=3, help="runs of each tree (default 3)")
    parser.add_argument("bench", help="the bench's file name in bench/, e.g. sim_speed.py")
    parser.add_argument("args", nargs=argparse.REMAINDER, help="passed to the bench")
    options = parser.parse_args()
    if options.rounds < 1:
        parser.error("--rounds must be at least 1")
    with tempfile.TemporaryDirectory(prefix="before-after-") as folder:
        old = export(options.rev, Path(folder))
        rev = subprocess.run(
            ["git", "-C", str(ROOT), "rev-parse", "--short", options.rev],
            capture_output=True, text=True, check=True,
        ).stdout.strip()  # fmt: skip
        here = subprocess.run(
            ["git", "-C", str(ROOT), "rev-parse", "--short", "HEAD"],
            capture_output=True, text=True, check=True,
        ).stdout.strip()  # fmt: skip
        dirty = subprocess.run(
            ["git", "-C", str(ROOT), "status", "--porcelain", "--untracked-files=no"],
            capture_output=True, text=True, check=True,
        ).stdout.strip()  # fmt: skip
        # the tree as it is: HEAD, and the changes not committed yet if there are any
        trees = (("old " + rev, old), ("new " + here + (" with changes" if dirty else ""), ROOT))
        figures: dict[str, list[list[str]]] = {name: [] for name, _tree in trees}
        print(f"{options.bench} {' '.join(options.args)}: {options.rounds} rounds, old first")
        for round_no in range(1, options.rounds + 1):
            for name, tree in trees:
                before = load()
                text, took = run_once(tree, options.bench, options.args)
                print(f"\n=== {name}, round {round_no}, {before}, {took:.1f} s")
                print(text.rstrip())
                figures[name].append([line for line in text.splitlines() if FIGURE.search(line)])
        print(f"\n=== figures, round by round ({load()} at the end)")
        for round_no in range(options.rounds):
            for name, _tree in trees:
                print(f"--- {name}, round {round_no + 1}")
                for line in figures[name][round_no]:
                    print(f"  {line}")


if __name__ == "__main__":
    main()
