"""Speed work keeps every run: the same command-line runs from this tree and an older revision,
compared byte for byte.

    python bench/same_runs.py --rev REV [--jobs 2] [--keep DIR] [--program FILE ARGS]...

Exports revision REV beside this tree (``bench/gitrev.py``) and runs one table of
``workbench run`` and ``workbench viple run`` commands from each tree: every built-in
algorithm on every bundled maze (its default noise, and realistic noise with two seeds), and
each bundled VIPLE program on the web and unity mazes (the same noise and seeds, keys typed,
a faster sensor report), each with ``--json`` and ``--record``. Both trees read the same copy
of this tree's mazes and programs, so every path a record holds is the same in both. Each
``--program FILE "ARGS"`` adds a program of your own with its own arguments (its sensors,
keys), e.g. a student's file.

Prints each run whose printed output or record differs (the first line where they part), then
how many runs were compared and how many differ; the exit status is 1 if any differs. A speed
change that keeps determinism prints ``0 differ``. The runs go through ``tests/cli_forker.py``
(one interpreter per tree, a fork per run), ``--jobs`` at a time.
"""

from __future__ import annotations

import argparse
import json
import os
import shlex
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
sys.path.insert(0, str(HERE))

from gitrev import export  # noqa: E402

#: simulated seconds of each run: long enough for many turns, touches and timer wakes
FSM_SECONDS = "200"
PROGRAM_SECONDS = "150"
#: each bundled program's robot: the web profile's sensors are the ones both programs read
PROGRAM_ARGS = ["--profile", "web"]


def algorithms() -> list[str]:
    return sorted(p.stem for p in (ROOT / "workbench" / "fsm" / "algorithms").glob("*.yaml"))


def noises() -> list[tuple[str, list[str]]]:
    """(name, arguments): the profile's default noise, then realistic noise with two seeds."""
    return [("default", [])] + [
        (f"realistic-{seed}", ["--noise", "realistic", "--seed", str(seed)]) for seed in (1, 2)
    ]


def cases(inputs: Path, extra: list[tuple[str, list[str]]]) -> list[tuple[str, list[str]]]:
    """(name, argv) of every run, the files read from ``inputs``."""
    mazes = sorted(p.stem for p in (inputs / "mazes").glob("*.txt"))
    table: list[tuple[str, list[str]]] = []
    for algorithm in algorithms():
        for maze in mazes:
            for noise, args in noises():
                argv = ["run", "--maze", str(inputs / "mazes" / f"{maze}.txt")]
                argv += ["--algorithm", algorithm, "--max-time", FSM_SECONDS, *args]
                table.append((f"fsm-{algorithm}-{maze}-{noise}", argv))
    bundled = sorted((inputs / "programs").glob("*.viple"))
    programs = [(p.stem, [str(p), *PROGRAM_ARGS]) for p in bundled] + extra
    for stem, program in programs:
        for maze in ("web", "unity-default"):
            for noise, args in noises():
                argv = ["viple", "run", *program, "--maze", str(inputs / "mazes" / f"{maze}.txt")]
                argv += ["--max-time", PROGRAM_SECONDS, *args]
                table.append((f"program-{stem}-{maze}-{noise}", argv))
    stem, program = programs[0]
    on_web = ["viple", "run", *program, "--maze", str(inputs / "mazes" / "web.txt")]
    typed = ["--keys", "w@0.5 a@2 release@2.6 w@3 space@6 d@7 release@7.4 w@8", "--max-time", "40"]
    table.append((f"program-{stem}-keys", [*on_web, *typed]))
    faster = ["--report-ms", "100", "--max-time", "100"]
    table.append((f"program-{stem}-report-100", [*on_web, *faster]))
    return table


def run_tree(tree: Path, table: list[tuple[str, list[str]]], out: Path, jobs: int) -> None:
    """Every run of ``table`` from ``tree``'s workbench, its output and record into ``out``."""
    out.mkdir()
    jobs_file = out / "jobs.json"
    jobs_list = [
        {"argv": [*argv, "--json", "--record", str(out / f"{name}.jsonl")], "out": str(out / name)}
        for name, argv in table
    ]
    jobs_file.write_text(json.dumps(jobs_list))
    forker = ["-m", "tests.cli_forker", str(jobs_file), str(out / "results.json")]
    subprocess.run(
        [sys.executable, *forker, "--jobs", str(jobs)],
        cwd=tree,
        env={**os.environ, "PYTHONPATH": str(tree)},
        check=True,
    )


def first_difference(old: Path, new: Path) -> str | None:
    """Where two files part, or None when they are the same bytes (a missing file counts)."""
    if not old.exists() and not new.exists():
        return None  # neither run wrote one (it stopped on an error both trees print)
    if not old.exists() or not new.exists():
        return f"{old.name}: {'missing before' if not old.exists() else 'missing now'}"
    a = old.read_bytes().splitlines()
    b = new.read_bytes().splitlines()
    for i, (x, y) in enumerate(zip(a, b, strict=False)):
        if x != y:
            return f"{old.name} line {i + 1}:\n    before {x[:160]!r}\n    now    {y[:160]!r}"
    if len(a) != len(b):
        return f"{old.name}: {len(a)} lines before, {len(b)} now"
    return None


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--rev", required=True, help="the older revision (a commit, tag or branch)")
    parser.add_argument("--jobs", type=int, default=2, help="runs at a time per tree (default 2)")
    parser.add_argument("--keep", type=Path, help="a new folder to keep both trees' outputs in")
    parser.add_argument(
        "--program", nargs=2, action="append", default=[], metavar=("FILE", "ARGS"),
        help='a VIPLE program and its arguments, e.g. --program W.viple "--sensor touch:1:front"',
    )  # fmt: skip
    options = parser.parse_args()
    with tempfile.TemporaryDirectory(prefix="same-runs-") as folder:
        work = Path(folder)
        inputs = work / "inputs"
        shutil.copytree(ROOT / "mazes", inputs / "mazes")
        shutil.copytree(ROOT / "programs", inputs / "programs")
        extra = []
        for number, (file, args) in enumerate(options.program):
            copy = inputs / "own" / str(number) / Path(file).name
            copy.parent.mkdir(parents=True)
            shutil.copyfile(file, copy)
            extra.append((f"own{number}-{Path(file).stem}", [str(copy), *shlex.split(args)]))
        table = cases(inputs, extra)
        (work / "old-tree").mkdir()
        old_tree = export(options.rev, work / "old-tree")
        start = time.monotonic()
        print(f"{len(table)} runs from each tree: {options.rev} and this tree")
        run_tree(old_tree, table, work / "before", options.jobs)
        run_tree(ROOT, table, work / "now", options.jobs)
        differ = 0
        for name, _argv in table:
            pairs = [(work / "before" / f, work / "now" / f) for f in (name, f"{name}.jsonl")]
            found = [d for old, new in pairs if (d := first_difference(old, new))]
            if found:
                differ += 1
                print(f"{name} differs:")
                for line in found:
                    print(f"  {line}")
        if options.keep is not None:
            shutil.copytree(work, options.keep, ignore=shutil.ignore_patterns("old-tree"))
        print(f"{len(table)} runs compared in {time.monotonic() - start:.0f} s: {differ} differ")
        sys.exit(1 if differ else 0)


if __name__ == "__main__":
    main()
