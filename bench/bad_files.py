"""Bad input files on the command line: how long the workbench takes to refuse each, and how
much memory it uses doing so.

Writes the corpus of tests/bad_files.py (deep YAML, alias bombs, NUL and non-UTF-8 bytes, NaN,
huge mazes, a 1 MB line, expressions past each limit) into a temporary folder, runs every
command that reads each file (``maze check``, ``run``, ``algorithms``, ``labs check``,
``ssh list-users``) in its own process, and prints per kind: the number of runs, how many
printed a traceback, the slowest run and the largest peak memory of one process (ru_maxrss
from os.wait4), then the same over all runs with getrusage(RUSAGE_CHILDREN). Timing and memory
vary from machine to machine: nothing here asserts on them.

    python bench/bad_files.py [--jobs N]
"""

from __future__ import annotations

import argparse
import resource
import sys
import tempfile
from collections import defaultdict
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from tests.bad_files import Outcome, run_corpus


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--jobs", type=int, default=4, help="commands run at once (default 4)")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as folder:
        outcomes = run_corpus(Path(folder), args.jobs)
    by_kind: dict[str, list[Outcome]] = defaultdict(list)
    for o in outcomes:
        by_kind[o.bad.kind].append(o)
    print(f"{'kind':6} {'runs':>5} {'traceback':>9} {'exit 0':>6} {'max s':>6} {'max MiB':>8}")
    for kind, runs in by_kind.items():
        tracebacks = sum("Traceback" in o.output for o in runs)
        zero = sum(o.code == 0 for o in runs)
        slowest = max(o.seconds for o in runs)
        rss = max(o.max_rss_kib for o in runs) / 1024
        print(f"{kind:6} {len(runs):5} {tracebacks:9} {zero:6} {slowest:6.2f} {rss:8.1f}")
    slow = max(outcomes, key=lambda o: o.seconds)
    big = max(outcomes, key=lambda o: o.max_rss_kib)
    children = resource.getrusage(resource.RUSAGE_CHILDREN)
    print(
        f"all    {len(outcomes):5} runs; slowest {slow.seconds:.2f} s ({slow.bad.filename}, "
        f"{slow.args[0]}); largest {big.max_rss_kib / 1024:.1f} MiB ({big.bad.filename})"
    )
    cpu = children.ru_utime + children.ru_stime
    print(f"RUSAGE_CHILDREN: max RSS {children.ru_maxrss / 1024:.1f} MiB, CPU {cpu:.1f} s")
    bad = [o for o in outcomes if "Traceback" in o.output or o.code == 0]
    for o in bad:
        print(f"NOT REFUSED CLEANLY: {o.bad.filename}: workbench {' '.join(o.args)} -> {o.code}")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
