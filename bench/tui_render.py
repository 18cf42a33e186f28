"""Maze view rendering cost: bytes to the terminal and time per frame, cached rows vs. naive.

Drives a small app holding only the maze view headless at 80x24 (``App.run_test``) on a
16x16-cell generated maze while the right-wall algorithm drives the robot in real time; a
20 Hz timer advances the session through the Pacer and calls ``MazeView.show``. The same run
is repeated with a naive variant of the widget that drops its row cache and refreshes the whole
widget on every tick. For each variant it prints:

  * bytes written to the terminal per second (the headless driver's ``write`` is wrapped),
  * mean and p95 time per frame: the tick's ``show()`` plus the screen update that paints it
    (compositor, line rendering and the write),
  * how many row strips the widget rendered,

then the naive/cached byte ratio. Targets: <= 5 KB/s, p95 frame <= 8 ms, >= 5x fewer bytes
than the naive variant.

Last, the whole workbench app runs right-wall for --app-seconds (30 s: it draws only when
something shows a change, one or two frames a second, so a p95 wants that many), chosen first
and then started as a student does; each frame's wall time and its CPU time (the main thread's,
without the waits for a core) are printed as mean and p95. Targets: <= 5 KB/s, p95 <= 8 ms,
and the speed round's p95 <= 5 ms.
"""

from __future__ import annotations

import argparse
import asyncio
import os
import statistics
import tempfile
import time
from dataclasses import dataclass, field

from textual.app import App, ComposeResult
from textual.drivers.headless_driver import HeadlessDriver
from textual.screen import Screen

from workbench.fsm.algorithms import load_algorithm
from workbench.fsm.machine import FsmController, bind_sensors, preset_sensors
from workbench.sim.clock import Pacer
from workbench.sim.generate import generate
from workbench.sim.maze import Maze
from workbench.sim.mazefile import write_maze
from workbench.sim.session import Session
from workbench.tui.app import make_app
from workbench.tui.widgets import MazeView
from workbench.tui.widgets.algorithm_state import AlgorithmState
from workbench.wire.settings import AppSettings

SIZE = (80, 24)
PROFILE = "unity"
ALGORITHM = "right-wall"


class NaiveMazeView(MazeView):
    """The maze view as a whole-widget repaint: every tick drops the cache and repaints it all."""

    def _apply(self, spans: dict[int, tuple[int, int]]) -> None:
        self._strips = [None] * len(self._strips)
        if self.is_mounted:
            self.refresh()


@dataclass
class Stats:
    written: int = 0
    ticks: int = 0
    frames: list[float] = field(default_factory=list)
    #: the main thread's CPU time of each screen update (without the wait for a core)
    frame_cpu: list[float] = field(default_factory=list)
    shows: list[float] = field(default_factory=list)
    pending_show: float | None = None
    measuring: bool = False


class CountingDriver(HeadlessDriver):
    """The headless driver, but the app renders its output for it and every byte is counted.

    (Textual skips producing terminal output altogether for a headless driver.)
    """

    stats: Stats | None = None

    @property
    def is_headless(self) -> bool:
        return False

    def write(self, data: str) -> None:
        stats = self.stats
        if stats is not None and stats.measuring:
            stats.written += len(data.encode("utf-8"))


class _Timing:
    """Times every screen update of the app being measured (a class-level hook on Screen)."""

    stats: Stats | None = None

    @classmethod
    def install(cls) -> None:
        original = Screen._on_timer_update

        def timed(screen: Screen) -> None:
            stats = cls.stats
            if stats is None or not stats.measuring:
                original(screen)
                return
            t0 = time.perf_counter()
            c0 = time.thread_time()
            original(screen)
            spent = time.perf_counter() - t0
            stats.frame_cpu.append(time.thread_time() - c0)
            if stats.pending_show is not None:
                spent += stats.pending_show
                stats.pending_show = None
            stats.frames.append(spent)

        Screen._on_timer_update = timed  # type: ignore[method-assign]


class RenderBench(App):
    def __init__(self, maze: Maze, view_class: type[MazeView], hz: float, speed: float) -> None:
        super().__init__()
        self.maze = maze
        self.view_class = view_class
        self.hz = hz
        self.speed = speed
        definition = load_algorithm(ALGORITHM)
        sensors = preset_sensors(definition, PROFILE)
        self.session = Session(maze, PROFILE, sensors, noise="off", seed=0)
        self.session.attach(
            FsmController(definition, {}, PROFILE),
            bind_sensors(definition, sensors, PROFILE),
            f"algorithm {ALGORITHM}",
        )
        self.pacer = Pacer(self.session, speed=speed)
        self.stats = Stats()
        self._last = 0.0

    def compose(self) -> ComposeResult:
        yield self.view_class(self.maze)

    def start_ticking(self) -> None:
        self._last = time.perf_counter()
        self.set_interval(1.0 / self.hz, self.tick)

    def tick(self) -> None:
        now = time.perf_counter()
        self.pacer.advance(now - self._last)
        self._last = now
        view = self.query_one(MazeView)
        t0 = time.perf_counter()
        view.show(self.session.snapshot(), self.session.world.cell)
        spent = time.perf_counter() - t0
        stats = self.stats
        if stats.measuring:
            stats.ticks += 1
            stats.shows.append(spent)
            if stats.pending_show is not None:  # the last tick changed nothing on screen
                stats.frames.append(stats.pending_show)
            stats.pending_show = spent


def p95(values: list[float]) -> float:
    if not values:
        return 0.0
    ordered = sorted(values)
    return ordered[min(len(ordered) - 1, round(0.95 * (len(ordered) - 1)))]


async def measure(
    maze: Maze, view_class: type[MazeView], seconds: float, hz: float, speed: float
) -> dict[str, float]:
    app = RenderBench(maze, view_class, hz, speed)
    async with app.run_test(size=SIZE) as pilot:
        await pilot.pause()
        stats = app.stats
        _Timing.stats = stats
        driver = app._driver
        assert isinstance(driver, HeadlessDriver)
        driver.__class__ = CountingDriver
        CountingDriver.stats = stats
        view = app.query_one(MazeView)
        built_before = view.strips_built
        app.start_ticking()
        stats.measuring = True
        t0 = time.perf_counter()
        await asyncio.sleep(seconds)
        elapsed = time.perf_counter() - t0
        stats.measuring = False
        if stats.pending_show is not None:
            stats.frames.append(stats.pending_show)
            stats.pending_show = None
        _Timing.stats = None
        CountingDriver.stats = None
        robot = view.robot_cell
        blocks = len(view._trail)
        built = view.strips_built - built_before
    return {
        "elapsed": elapsed,
        "bytes": stats.written,
        "bytes_per_s": stats.written / elapsed,
        "ticks": stats.ticks,
        "frames": len(stats.frames),
        "frame_mean_ms": 1000 * statistics.fmean(stats.frames) if stats.frames else 0.0,
        "frame_p95_ms": 1000 * p95(stats.frames),
        "show_mean_ms": 1000 * statistics.fmean(stats.shows) if stats.shows else 0.0,
        "show_p95_ms": 1000 * p95(stats.shows),
        "strips": built,
        "blocks_visited": blocks,
        "robot": robot,
        "sim_time": app.session.world.time,
    }


async def measure_app(maze: Maze, seconds: float, hz: float, speed: float) -> dict[str, float]:
    """The whole workbench app (maze view, side panels, run status) with right-wall running."""
    with tempfile.TemporaryDirectory() as tmp:
        path = os.path.join(tmp, "station-maze.txt")
        write_maze(path, maze)
        app = make_app(AppSettings(path, PROFILE, noise="off", tick_hz=hz))
        app.holds_process = True  # the bench's process holds this app as ``workbench`` does
        async with app.run_test(size=SIZE) as pilot:
            await pilot.pause()
            station = app.station
            station.pacer.speed = speed
            station.select_algorithm(ALGORITHM)
            station.apply_algorithm_preset()
            # as a student does it: the algorithm is chosen (and the panel shows it), then
            # the run starts, in the measured stretch
            panel = app.screen.query_one(AlgorithmState)
            for _ in range(100):
                if panel.states[0]:
                    break
                await pilot.pause(0.05)
            else:
                raise SystemExit(f"the algorithm panel never showed {ALGORITHM}")
            await pilot.pause()
            station.start()
            stats = Stats()
            _Timing.stats = stats
            driver = app._driver
            assert isinstance(driver, HeadlessDriver)
            driver.__class__ = CountingDriver
            CountingDriver.stats = stats
            stats.measuring = True
            frames_before = app.frames
            t0 = time.perf_counter()
            await asyncio.sleep(seconds)
            elapsed = time.perf_counter() - t0
            stats.measuring = False
            _Timing.stats = None
            CountingDriver.stats = None
            return {
                "elapsed": elapsed,
                "bytes": stats.written,
                "bytes_per_s": stats.written / elapsed,
                "ticks": app.frames - frames_before,
                "frames": len(stats.frames),
                "frame_mean_ms": 1000 * statistics.fmean(stats.frames) if stats.frames else 0.0,
                "frame_p95_ms": 1000 * p95(stats.frames),
                "frame_cpu_p95_ms": 1000 * p95(stats.frame_cpu),
                "sim_time": station.session.world.time,
            }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seconds", type=float, default=10.0, help="real time per variant")
    parser.add_argument(
        "--app-seconds",
        type=float,
        default=30.0,
        help="real time of the whole app's run (it draws a frame only when something shows "
        "a change, about one or two a second: a p95 wants some dozens)",
    )
    parser.add_argument("--hz", type=float, default=20.0, help="ticks per second")
    parser.add_argument("--speed", type=float, default=1.0, help="simulation speed factor")
    parser.add_argument("--seed", type=int, default=1, help="maze generator seed")
    args = parser.parse_args()

    maze = generate(16, 16, args.seed)
    _Timing.install()
    print(
        f"maze view render: {maze.name} ({maze.width}x{maze.height} blocks), terminal "
        f"{SIZE[0]}x{SIZE[1]}, {args.hz:g} Hz for {args.seconds:g} s, {PROFILE} {ALGORITHM} "
        f"at {args.speed:g}x"
    )
    results = {}
    for label, view_class in (("cached rows", MazeView), ("naive repaint", NaiveMazeView)):
        results[label] = r = asyncio.run(
            measure(maze, view_class, args.seconds, args.hz, args.speed)
        )
        print(
            f"  {label:<14} {r['bytes_per_s'] / 1000:7.2f} KB/s"
            f"  frame mean {r['frame_mean_ms']:5.2f} ms  p95 {r['frame_p95_ms']:5.2f} ms"
            f"  (show mean {r['show_mean_ms']:.2f} ms, p95 "
            f"{r['show_p95_ms']:.2f} ms)  {r['ticks']} ticks, {r['frames']} frames, "
            f"{r['strips']} rows rendered, {r['blocks_visited']} blocks visited, "
            f"{r['sim_time']:.1f} s simulated"
        )
    cached = results["cached rows"]
    naive = results["naive repaint"]
    ratio = naive["bytes"] / cached["bytes"] if cached["bytes"] else float("inf")
    print(f"  naive/cached bytes: {ratio:.1f}x")

    def verdict(ok: bool) -> str:
        return "ok" if ok else "MISSED"

    full = asyncio.run(measure_app(maze, args.app_seconds, args.hz, args.speed))
    print(
        f"  whole app      {full['bytes_per_s'] / 1000:7.2f} KB/s"
        f"  frame mean {full['frame_mean_ms']:5.2f} ms  p95 {full['frame_p95_ms']:5.2f} ms"
        f" (CPU p95 {full['frame_cpu_p95_ms']:.2f} ms)"
        f"  ({full['ticks']} ticks, {full['frames']} frames: maze view, sensor readings, "
        f"algorithm state and run status all live; {full['sim_time']:.1f} s simulated)"
    )

    print(
        f"  whole app targets: <= 5 KB/s {verdict(full['bytes_per_s'] <= 5000)}, "
        f"p95 frame <= 8 ms {verdict(full['frame_p95_ms'] <= 8.0)}, "
        f"speed round's p95 frame <= 5 ms {verdict(full['frame_p95_ms'] <= 5.0)}"
    )
    print(
        f"  maze view targets: <= 5 KB/s {verdict(cached['bytes_per_s'] <= 5000)}, "
        f"p95 frame <= 8 ms {verdict(cached['frame_p95_ms'] <= 8.0)}, "
        f">= 5x fewer bytes than naive {verdict(ratio >= 5.0)}"
    )


if __name__ == "__main__":
    main()
