"""A run's path drawn on its maze, to scale: walls, start and exits, the path coloured by time,
its turns, collisions and touches, and the sensors' beams at chosen moments.

Every group of marks has an id in the SVG (``maze-walls``, ``robot-path``, ``turns``,
``collisions``, ``touches``, ``beams``...), so a picture can be checked by what it holds.
matplotlib is imported by the functions that draw, never when this module is imported.
"""

from __future__ import annotations

import bisect
import itertools
import math
import re
from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

from workbench.sim.maze import HEADINGS
from workbench.sim.sensors import MOUNT_ANGLES

from .runs import PictureRun
from .series import event_ticks, turn_ticks
from .words import caption

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure
    from matplotlib.path import Path as MplPath

_WALL_RUN = re.compile("#+")
#: how many pieces of one colour the time-coloured path is drawn in
TIME_PIECES = 96
WALL_COLOUR = "#3a3f4b"
EXIT_COLOUR = "#2ca02c"
START_COLOUR = "#1f77b4"
COLLISION_COLOUR = "#d62728"
TOUCH_COLOUR = "#ff7f0e"
BEAM_COLOUR = "#e377c2"


def wall_rectangles(run: PictureRun) -> list[tuple[int, int, int, int]]:
    """The maze's wall blocks as few rectangles (x, y, width, height in blocks): each row's
    runs of wall, a run carried down while the rows below have the same run."""
    maze = run.maze
    open_runs: dict[tuple[int, int], int] = {}  # (x, width) -> first row
    out: list[tuple[int, int, int, int]] = []
    for y in range(maze.height + 1):
        row = maze.rows[y] if y < maze.height else ""
        runs = {(m.start(), m.end() - m.start()) for m in _WALL_RUN.finditer(row)}
        for key in [k for k in open_runs if k not in runs]:
            top = open_runs.pop(key)
            out.append((key[0], top, key[1], y - top))
        for key in runs:
            open_runs.setdefault(key, y)
    return sorted(out, key=lambda r: (r[1], r[0]))


def _rectangles_path(rects: Sequence[tuple[float, float, float, float]]) -> MplPath:
    from matplotlib.path import Path as MplPath

    vertices: list[tuple[float, float]] = []
    codes: list[Any] = []
    for x, y, w, h in rects:
        vertices += [(x, y), (x + w, y), (x + w, y + h), (x, y + h), (x, y)]
        codes += [MplPath.MOVETO, MplPath.LINETO, MplPath.LINETO, MplPath.LINETO, MplPath.CLOSEPOLY]
    return MplPath(vertices or [(0.0, 0.0)], codes or [MplPath.MOVETO])


def draw_maze(ax: Axes, run: PictureRun, *, small: bool = False) -> None:
    """The maze to scale (y grows down, as in the maze file), its start and exits."""
    from matplotlib.patches import PathPatch, Polygon

    maze, cell = run.maze, run.cell
    rects = wall_rectangles(run)
    width, height = maze.width * cell, maze.height * cell
    ax.set_xlim(0, width)
    ax.set_ylim(height, 0)
    ax.set_aspect("equal")
    ax.set_facecolor("white")
    ax.set_xticks([])
    ax.set_yticks([])
    # (add_artist, not add_patch: the limits are set above, and working them out from
    # thousands of walls would take seconds)
    walls = PathPatch(
        _rectangles_path([(x * cell, y * cell, w * cell, h * cell) for x, y, w, h in rects]),
        facecolor=WALL_COLOUR,
        edgecolor="none",
        linewidth=0,
        gid="maze-walls",
    )
    ax.add_artist(walls)
    exits = [(x * cell, y * cell, cell, cell) for x, y in maze.exits]
    if exits:
        ax.add_artist(
            PathPatch(
                _rectangles_path(exits),
                facecolor=EXIT_COLOUR,
                alpha=0.35,
                edgecolor=EXIT_COLOUR,
                linewidth=1,
                gid="maze-exits",
                label=None if small else "exit",
            )
        )
    if maze.start is not None:
        sx, sy = maze.start
        dx, dy = HEADINGS[maze.heading]
        cx, cy, r = (sx + 0.5) * cell, (sy + 0.5) * cell, 0.35 * cell
        tip = (cx + dx * r, cy + dy * r)
        back = [
            (cx - dx * r * 0.6 - dy * r * 0.7, cy - dy * r * 0.6 + dx * r * 0.7),
            (cx - dx * r * 0.6 + dy * r * 0.7, cy - dy * r * 0.6 - dx * r * 0.7),
        ]
        ax.add_artist(
            Polygon(
                [tip, *back],
                closed=True,
                facecolor="none",
                edgecolor=START_COLOUR,
                linewidth=1.5,
                gid="maze-start",
                label=None if small else "start",
            )
        )


def _time_path(ax: Axes, run: PictureRun, fig: Figure) -> None:
    from matplotlib.collections import LineCollection

    replay = run.replay
    xs = [p.x for p in replay.poses]
    ys = [p.y for p in replay.poses]
    # the whole path in one line, one point per recorded pose, under its colours
    ax.plot(
        xs, ys, color="#202020", linewidth=2.8, solid_capstyle="round", gid="robot-path", zorder=3
    )
    n = len(xs)
    pieces = max(1, min(TIME_PIECES, n - 1))
    bounds = [round(k * (n - 1) / pieces) for k in range(pieces + 1)]
    segments = []
    middles = []
    for a, b in itertools.pairwise(bounds):
        if b <= a:
            continue
        segments.append(list(zip(xs[a : b + 1], ys[a : b + 1], strict=True)))
        middles.append((replay.times[a] + replay.times[b]) / 2)
    if not segments:  # a record of one tick: a dot
        segments, middles = [[(xs[0], ys[0]), (xs[0], ys[0])]], [replay.times[0]]
    lines = LineCollection(
        segments,
        cmap="viridis",
        linewidths=1.6,
        capstyle="round",
        gid="robot-path-time",
        zorder=4,
    )
    lines.set_array(middles)
    lines.set_clim(replay.times[0], max(replay.times[-1], replay.times[0] + 1e-9))
    ax.add_collection(lines)
    bar = fig.colorbar(lines, ax=ax, shrink=0.8, pad=0.02)
    bar.set_label("time (s)")


def _marks(ax: Axes, run: PictureRun, ticks: list[int], gid: str, **style: Any) -> None:
    poses = run.replay.poses
    ax.plot(
        [poses[i].x for i in ticks],
        [poses[i].y for i in ticks],
        linestyle="none",
        gid=gid,
        zorder=6,
        **style,
    )


def beam_index(run: PictureRun, t: float) -> int:
    """The tick a moment ``t`` (simulated seconds) shows: the last one at or before it."""
    return max(0, bisect.bisect_right(run.replay.times, t) - 1)


def draw_beams(ax: Axes, run: PictureRun, moments: Sequence[float]) -> None:
    """The robot at each moment, with each distance sensor's beam to the wall it saw and each
    touch sensor's side (filled when it touched)."""
    from matplotlib.patches import Circle, Wedge

    profile = run.profile
    replay = run.replay
    for k, t in enumerate(moments):
        frame = replay.frame(beam_index(run, t))
        pose = frame.pose
        a = math.radians(pose.heading)
        gid = f"beams-{k + 1}"
        ax.add_artist(
            Circle(
                (pose.x, pose.y),
                profile.robot_radius,
                facecolor="white",
                edgecolor="black",
                linewidth=1,
                zorder=7,
                gid=f"robot-{k + 1}",
            )
        )
        r = profile.robot_radius
        ax.plot(
            [pose.x, pose.x + math.cos(a) * r],
            [pose.y, pose.y + math.sin(a) * r],
            color="black",
            linewidth=1,
            zorder=8,
        )
        xs: list[float] = []
        ys: list[float] = []
        for spec in replay.sensors:
            reading = frame.sensors.get(spec.port)
            angle = a + math.radians(MOUNT_ANGLES[spec.mount])
            dx, dy = math.cos(angle), math.sin(angle)
            if spec.kind == "distance" and reading is not None:
                offset = profile.sensor_offset(spec.mount)
                reach = min(float(reading), profile.sensor_range)
                x0, y0 = pose.x + dx * offset, pose.y + dy * offset
                xs += [x0, x0 + dx * reach, math.nan]
                ys += [y0, y0 + dy * reach, math.nan]
                ax.annotate(
                    f"{spec.port}: {reading:.0f}"
                    if profile.unit == "px"
                    else f"{spec.port}: {reading:.2f}",
                    (x0 + dx * reach, y0 + dy * reach),
                    fontsize=7,
                    color=BEAM_COLOUR,
                    zorder=9,
                    xytext=(2, 2),
                    textcoords="offset points",
                )
            elif spec.kind == "touch":
                mid = math.degrees(angle)
                ax.add_artist(
                    Wedge(
                        (pose.x, pose.y),
                        r * 1.25,
                        mid - 45,
                        mid + 45,
                        width=r * 0.35,
                        facecolor=COLLISION_COLOUR if reading else "none",
                        edgecolor=COLLISION_COLOUR,
                        linewidth=0.8,
                        zorder=8,
                    )
                )
        ax.plot(
            xs,
            ys,
            color=BEAM_COLOUR,
            linewidth=1.2,
            linestyle="--",
            zorder=7,
            gid=gid,
            label="beams" if k == 0 else None,
        )
        ax.annotate(
            f"t {frame.t:.1f} s",
            (pose.x, pose.y),
            fontsize=7,
            zorder=9,
            xytext=(6, -10),
            textcoords="offset points",
        )


def draw_path_figure(fig: Figure, run: PictureRun, moments: Sequence[float]) -> None:
    """Kind ``path``: the maze, the path coloured by time, its marks, beams and caption."""
    ax = fig.add_subplot(1, 1, 1)
    draw_maze(ax, run)
    _time_path(ax, run, fig)
    replay = run.replay
    first, last = replay.poses[0], replay.poses[-1]
    ax.plot(
        [first.x],
        [first.y],
        marker="o",
        color=START_COLOUR,
        markersize=7,
        zorder=6,
        linestyle="none",
        label="first pose",
        gid="first-pose",
    )
    ax.plot(
        [last.x],
        [last.y],
        marker="s",
        color="black",
        markersize=6,
        zorder=6,
        linestyle="none",
        label="last pose",
        gid="last-pose",
    )
    turns = turn_ticks(replay)
    collisions = event_ticks(replay, "collision")
    touches = event_ticks(replay, "touch")
    _marks(
        ax,
        run,
        turns,
        "turns",
        marker="o",
        markersize=5,
        markerfacecolor="none",
        markeredgecolor="#9467bd",
        markeredgewidth=1.2,
        label=f"turn ({len(turns)})",
    )
    _marks(
        ax,
        run,
        collisions,
        "collisions",
        marker="X",
        markersize=9,
        color=COLLISION_COLOUR,
        label=f"collision ({len(collisions)})",
    )
    _marks(
        ax,
        run,
        touches,
        "touches",
        marker="D",
        markersize=6,
        color=TOUCH_COLOUR,
        label=f"touch ({len(touches)})",
    )
    draw_beams(ax, run, moments)
    ax.legend(loc="upper left", bbox_to_anchor=(0.0, -0.01), ncol=4, fontsize=8, frameon=False)
    fig.suptitle(f"Path of {run.replay.driver.short}", fontsize=12)
    ax.set_title(caption(run), fontsize=8, loc="left")
