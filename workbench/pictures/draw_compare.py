"""Several runs on one maze side by side: their paths in small multiples and a bar chart of
each graded figure (time, distance, turning, turns, collisions), for the lab's comparison
questions. matplotlib is imported by the function that draws, never when this module is."""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from typing import TYPE_CHECKING

from .draw_maze import draw_maze
from .runs import PictureRun
from .series import event_ticks, label
from .words import Figures, figures, record_stop_short

if TYPE_CHECKING:
    from matplotlib.figure import Figure

#: the graded figures the bar charts show: title, and the figure of a run
BARS: tuple[tuple[str, Callable[[Figures], float]], ...] = (
    ("time (s)", lambda f: f.time),
    ("distance (blocks)", lambda f: f.blocks),
    ("turning (°)", lambda f: f.turn_degrees),
    ("turns", lambda f: f.turns),
    ("collisions", lambda f: f.collisions),
)


def run_label(k: int, run: PictureRun) -> str:
    """``1 right-wall (run-001.jsonl)``: how the picture names its ``k``-th run."""
    return f"{k + 1} {label(run.replay.driver.short)} ({label(run.name)})"


def draw_compare_figure(fig: Figure, runs: Sequence[PictureRun]) -> None:
    """Kind ``compare``: one small maze per run with its path, then the bars."""
    n = len(runs)
    columns = min(n, 4)
    map_rows = math.ceil(n / columns)
    # as many grid columns as both the maps' and the bars' rows divide evenly
    width = math.lcm(columns, len(BARS))
    grid = fig.add_gridspec(map_rows + 1, width, height_ratios=[3.0] * map_rows + [2.0])
    span, bar_span = width // columns, width // len(BARS)
    for k, run in enumerate(runs):
        row, col = divmod(k, columns)
        ax = fig.add_subplot(grid[row, col * span : (col + 1) * span])
        draw_maze(ax, run, small=True)
        poses = run.replay.poses
        colour = f"C{k % 10}"
        ax.plot(
            [p.x for p in poses],
            [p.y for p in poses],
            color=colour,
            linewidth=1.4,
            gid=f"robot-path-{k + 1}",
            zorder=3,
        )
        hits = event_ticks(run.replay, "collision")
        ax.plot(
            [poses[i].x for i in hits],
            [poses[i].y for i in hits],
            linestyle="none",
            marker="X",
            color="#d62728",
            markersize=6,
            gid=f"collisions-{k + 1}",
            zorder=4,
        )
        f = figures(run)
        out = f"out at {f.exit_time:.1f} s" if f.exit_time is not None else "not out"
        stop = record_stop_short(run)
        if stop is not None:
            out += f" | {stop}"
        ax.set_title(f"{run_label(k, run)}\n{out}", fontsize=7)
    numbers = [figures(run) for run in runs]
    for j, (title, value) in enumerate(BARS):
        ax = fig.add_subplot(grid[map_rows, j * bar_span : (j + 1) * bar_span])
        values = [float(value(f)) for f in numbers]
        bars = ax.bar(
            range(1, n + 1), values, color=[f"C{k % 10}" for k in range(n)], gid=f"bars-{j + 1}"
        )
        ax.bar_label(bars, labels=[_short(v) for v in values], fontsize=6)
        ax.set_title(title, fontsize=8)
        ax.set_xticks(range(1, n + 1))
        ax.tick_params(labelsize=7)
        ax.margins(y=0.2)
        ax.set_ylim(bottom=0, top=None if max(values, default=0) > 0 else 1)
    first = runs[0]
    fig.suptitle(
        f"{label(first.maze.name or 'unnamed maze')} ({first.profile.name}): "
        f"{n} run{'' if n == 1 else 's'} side by side",
        fontsize=11,
    )


def _short(value: float) -> str:
    return f"{value:.0f}" if value >= 100 or value == int(value) else f"{value:.1f}"
