"""The instructor's console with a class at work: how long a student's "ready" takes to show
as a request on the console's screen.

Fills a fresh store (the SQLite file of a temporary data folder, or ``--db URL``, an empty
PostgreSQL database) with STUDENTS students at the first exercise, runs the console headless,
and from a thread of its own plays the class: every student's progress is saved again about
once a second (objectives passing and failing), and every INTERVAL seconds one student asks for
sign-off. For each request it notes the time from the ask (before the store is written) to the
console's first screen update that lists it, and declines each request once seen (so the queue
stays short, as in a lab). Prints the number of requests, the median, the 95th percentile and
the slowest, and how long one read of the whole class took. Timings vary with the machine:
nothing here asserts on them.

    python bench/console.py [--students 60] [--requests 40] [--interval 0.5] [--db URL]
"""

from __future__ import annotations

import argparse
import asyncio
import json
import statistics
import sys
import tempfile
import threading
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from workbench.labs.checks import ExerciseProgress, ObjectiveState
from workbench.labs.classview import read_class
from workbench.labs.model import load_labs
from workbench.labs.store.store import Store
from workbench.tui.console_app import ConsoleApp
from workbench.tui.screens.console import ClassRead, ConsoleScreen


def progress(lab_id: str, exercise, turn: int) -> dict:
    states = [
        ObjectiveState(o.kind, o.text, (turn + i) % 3 != 0, "checked", {"turn": turn})
        for i, o in enumerate(exercise.objectives)
    ]
    return json.loads(ExerciseProgress(lab_id, exercise.id, states).to_json())


class Class:
    """The students, played from one thread with a store of its own."""

    def __init__(self, data: Path, db: str | None, students: int, interval: float) -> None:
        self.store = Store.open(data, db=db)
        lab = load_labs()[0]
        self.lab, self.exercise = lab.id, lab.exercises[0]
        self.names = [f"student{n:02d}" for n in range(students)]
        self.interval = interval
        #: student -> when they asked (time.monotonic), until the console shows it
        self.asked: dict[str, float] = {}
        #: requests the console has shown, for the player to decline (the queue stays short)
        self.seen: list[int] = []
        self.lock = threading.Lock()
        self.stop = threading.Event()
        for name in self.names:
            self.store.progress.set_place(name, self.lab, self.exercise.id)
            self.store.progress.save(name, self.lab, self.exercise.id, self.progress(0))

    def progress(self, turn: int) -> dict:
        return progress(self.lab, self.exercise, turn)

    def play(self) -> None:
        turn, next_ask, asker = 0, time.monotonic(), 0
        per_save = 1.0 / len(self.names)
        while not self.stop.is_set():
            turn += 1
            name = self.names[turn % len(self.names)]
            self.store.progress.save(name, self.lab, self.exercise.id, self.progress(turn))
            with self.lock:
                seen, self.seen = self.seen, []
            for entry_id in seen:
                self.store.queue.decline(entry_id, "bench", "seen")
            if time.monotonic() >= next_ask:
                who = self.names[asker % len(self.names)]
                asker += 1
                with self.lock:
                    if who not in self.asked:
                        self.asked[who] = time.monotonic()
                        self.store.queue.request(who, "", who, self.lab, self.exercise.id)
                next_ask += self.interval
            self.stop.wait(per_save)


async def run(args: argparse.Namespace) -> int:
    with tempfile.TemporaryDirectory() as folder:
        data = Path(folder) / "data"
        playing = Class(data, args.db, args.students, args.interval)
        app = ConsoleApp(Store.open(data, db=args.db), load_labs())
        delays: list[float] = []
        reads: list[float] = []
        done = asyncio.Event()

        def shown(message: ClassRead) -> None:
            if message.view is None:
                return
            now = time.monotonic()
            with playing.lock:
                for entry in message.view.queue:
                    asked = playing.asked.pop(entry.student, None)
                    if asked is not None:
                        delays.append(now - asked)
                        playing.seen.append(entry.id)
            if len(delays) >= args.requests:
                done.set()

        async with app.run_test(size=(100, 80)) as pilot:
            screen = app.screen
            assert isinstance(screen, ConsoleScreen)
            screen.on_shown.append(shown)
            player = threading.Thread(target=playing.play, daemon=True)
            player.start()
            try:
                while not done.is_set():
                    await asyncio.wait_for(done.wait(), timeout=args.requests * 5)
            finally:
                playing.stop.set()
                player.join()
            await pilot.pause()
            # one read of the whole class, as the console's thread makes it
            labs = load_labs()
            for _ in range(10):
                start = time.perf_counter()
                await asyncio.to_thread(read_class, playing.store, labs)
                reads.append(time.perf_counter() - start)
        playing.store.close()
    delays.sort()
    p95 = delays[max(0, round(0.95 * len(delays)) - 1)]
    store = "PostgreSQL" if args.db else "SQLite"
    print(f"console with {args.students} students on {store}, {len(delays)} requests")
    print(f"ready -> on the console: median {statistics.median(delays):.3f} s, "
          f"p95 {p95:.3f} s, slowest {delays[-1]:.3f} s")  # fmt: skip
    print(f"one read of the class: median {statistics.median(reads) * 1000:.1f} ms")
    print(f"target: ready -> shown p95 <= 0.2 s: {'met' if p95 <= 0.2 else 'NOT met'}")
    return 0


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--students", type=int, default=60)
    parser.add_argument("--requests", type=int, default=40)
    parser.add_argument("--interval", type=float, default=0.5, help="seconds between asks")
    parser.add_argument("--db", help="an empty PostgreSQL database (default: SQLite)")
    return asyncio.run(run(parser.parse_args()))


if __name__ == "__main__":
    raise SystemExit(main())
