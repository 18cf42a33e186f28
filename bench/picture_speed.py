"""How long a picture takes and how large it is, and what the pictures cost the app's start-up.

1. A 200x200 block maze (a generated 99x99-cell maze with one more wall row and column) and
   30-minute runs on it (right-wall, cut at its time limit; two more algorithms for the
   side-by-side picture): each kind as SVG and PNG, the CPU time to read the records (the
   replay's reader, which checks every tick) and to draw and save the picture, and the file's
   size, against the targets (under 2 s, under 5 MB).
2. The app's start-up before and after, in one run: --compare REV (default: where this
   branch left main, ``git merge-base HEAD main``) is exported
   beside this tree (bench/gitrev.py) and each tree's app is made in fresh processes, in turn,
   --starts times: the seconds from the first import to a made app (the served app's entry
   point, workbench.cli.served, and make_app; in CPU seconds, as the other figures, so they
   hold up while other work runs on the machine), its peak resident memory, the modules loaded,
   and whether matplotlib is among them.

    .venv/bin/python bench/picture_speed.py [--compare REV] [--starts N]
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from gitrev import export  # noqa: E402

from workbench.control.headless import AlgorithmPilot, RunSpec, run  # noqa: E402
from workbench.sim.generate import generate  # noqa: E402
from workbench.sim.mazeio import save_maze  # noqa: E402

SECONDS = 2.0
BYTES = 5_000_000
RUN_SECONDS = 1800.0
ALGORITHMS = ("right-wall", "farthest-distance", "first-working-solution")

#: a made app, as the lab server makes one: its time, memory and modules, as one JSON line
START = """
import json, sys, time
t0 = time.process_time()
import workbench.cli.served
from workbench.tui.app import make_app
from workbench.wire.settings import AppSettings
app = make_app(AppSettings(paused=True, student="ana"))
took = time.process_time() - t0
print(json.dumps({
    "seconds": took,
    # (VmHWM, not ru_maxrss: the latter keeps the forked bench's size across exec)
    "rss_kib": next(int(l.split()[1]) for l in open("/proc/self/status") if l.startswith("VmHWM")),
    "modules": len(sys.modules),
    "matplotlib": "matplotlib" in sys.modules,
}))
"""


def big_maze(folder: Path) -> Path:
    maze = generate(99, 99, 1)
    maze = dataclasses.replace(
        maze,
        rows=(*(r + "#" for r in maze.rows), "#" * (maze.width + 1)),
        name="200x200 blocks",
    )
    assert maze.width == maze.height == 200 and not maze.validate()
    path = folder / "big.txt"
    save_maze(path, maze)
    return path


def records(folder: Path, maze: Path) -> list[Path]:
    out = []
    for name in ALGORITHMS:
        record = folder / f"{name}.jsonl"
        t0 = time.perf_counter()
        result = run(RunSpec(str(maze), AlgorithmPilot(name), profile="erobotic",
                             max_time=RUN_SECONDS, record=str(record)))  # fmt: skip
        ticks = sum(1 for _ in record.open()) - 2
        print(
            f"  {name}: {result.metrics['sim_time']:.0f} s simulated, {ticks:,} ticks, "
            f"record {record.stat().st_size:,} bytes ({time.perf_counter() - t0:.1f} s to run)"
        )
        out.append(record)
    return out


def verdict(ok: bool) -> str:
    return "met" if ok else "NOT met"


def pictures(folder: Path, made: list[Path]) -> None:
    t0 = time.process_time()
    import matplotlib.figure  # noqa: F401  (once, as the first picture of a session pays it)

    print(f"  matplotlib's import: {time.process_time() - t0:.2f} CPU s (once per process)")
    from workbench.pictures.render import PictureSpec, save_picture
    from workbench.pictures.runs import load_runs

    for kind, paths in (("path", made[:1]), ("time", made[:1]), ("compare", made)):
        for fmt in ("svg", "png"):
            t0, w0 = time.process_time(), time.perf_counter()
            runs = load_runs(paths)
            read = time.process_time() - t0
            target = folder / f"{kind}.{fmt}"
            at = (600.0, 1200.0) if kind == "path" else ()
            save_picture(runs, target, PictureSpec(kind, at=at))
            took = time.process_time() - t0
            wall = time.perf_counter() - w0
            size = target.stat().st_size
            print(
                f"  {kind:7} {fmt}: {took:.2f} CPU s = {read:.2f} reading {len(paths)} "
                f"record{'s' if len(paths) > 1 else ''} + {took - read:.2f} drawing and "
                f"saving ({wall:.2f} s wall), {size:,} bytes"
            )
            print(
                f"    target: drawn and saved < {SECONDS:g} s, file < {BYTES / 1e6:g} MB: "
                f"{verdict(took - read < SECONDS and size < BYTES)}; with the reading "
                f"< {SECONDS:g} s: {verdict(took < SECONDS)}"
            )


def start_once(tree: Path, home: Path) -> dict:
    env = {**os.environ, "PYTHONPATH": str(tree), "HOME": str(home)}
    env.pop("WORKBENCH_APP", None)
    done = subprocess.run(
        [sys.executable, "-c", START], cwd=home, env=env, capture_output=True, text=True,
        timeout=300, check=True,
    )  # fmt: skip
    return json.loads(done.stdout.strip().splitlines()[-1])


def start_up(rev: str, starts: int) -> None:
    with tempfile.TemporaryDirectory(prefix="picture-bench-") as tmp:
        (Path(tmp) / "before").mkdir()
        before = export(rev, Path(tmp) / "before")
        home = Path(tmp) / "home"
        home.mkdir()
        trees = {f"before ({rev})": before, "after (this tree)": ROOT}
        # both trees' modules compiled beforehand, and one start of each not counted, so that
        # neither pays for compiling or a cold file cache
        for tree in trees.values():
            subprocess.run(
                [sys.executable, "-m", "compileall", "-q", str(tree / "workbench")], check=True
            )
        for tree in trees.values():
            start_once(tree, home)
        seen: dict[str, list[dict]] = {name: [] for name in trees}
        for _ in range(starts):
            for name, tree in trees.items():  # in turn, so both see the same load
                seen[name].append(start_once(tree, home))
        for name, runs in seen.items():
            seconds = statistics.median(r["seconds"] for r in runs)
            rss = statistics.median(r["rss_kib"] for r in runs) / 1024
            modules = statistics.median(r["modules"] for r in runs)
            loaded = any(r["matplotlib"] for r in runs)
            print(
                f"  {name:20} {seconds:.3f} CPU s to a made app (median of {starts}), "
                f"{rss:.1f} MiB peak resident, {modules:.0f} modules, matplotlib "
                f"{'LOADED' if loaded else 'not loaded'}"
            )
        b, a = (seen[n] for n in trees)
        ratio = statistics.median(r["seconds"] for r in a) / statistics.median(
            r["seconds"] for r in b
        )
        grew = statistics.median(r["rss_kib"] for r in a) - statistics.median(
            r["rss_kib"] for r in b
        )
        mpl = any(r["matplotlib"] for r in a)
        print(f"  after/before start-up time {ratio:.2f}, memory {grew / 1024:+.1f} MiB")
        print(f"  target: matplotlib not loaded by the app: {verdict(not mpl)}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--compare", metavar="REV", help="default: git merge-base HEAD main")
    parser.add_argument("--starts", type=int, default=5)
    args = parser.parse_args()
    print(f"load average {os.getloadavg()[0]:.2f}, {os.cpu_count()} processors")
    with tempfile.TemporaryDirectory(prefix="picture-bench-") as tmp:
        folder = Path(tmp)
        print("records (a 200x200 block maze, runs of up to 30 minutes):")
        made = records(folder, big_maze(folder))
        print("pictures:")
        pictures(folder, made)
    rev = args.compare or subprocess.run(
        ["git", "-C", str(ROOT), "merge-base", "HEAD", "main"],
        capture_output=True, text=True, check=True,
    ).stdout.strip()[:12]  # fmt: skip
    print("the app's start-up:")
    start_up(rev, args.starts)


if __name__ == "__main__":
    main()
