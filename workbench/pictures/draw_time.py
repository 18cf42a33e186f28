"""A run over time: each sensor's readings, the wheel powers (and turns asked for), and the
FSM's states or the program's active flows as a band, on one time axis.

matplotlib is imported by the function that draws, never when this module is imported.
"""

from __future__ import annotations

import bisect
from typing import TYPE_CHECKING

from workbench.sim.driver import Driver

from .runs import PictureRun
from .series import event_ticks, powers, sensor_series, state_spans
from .words import figure_lines, heading, record_stop

if TYPE_CHECKING:
    from matplotlib.figure import Figure

#: columns of the state band (a state shorter than one column may not show)
BAND_COLUMNS = 2000
#: the most states the band's legend names
LEGEND_STATES = 12


def band_title(driver: Driver) -> str:
    return "active flows" if driver.kind == "program" else "state"


def draw_time_figure(fig: Figure, run: PictureRun) -> None:
    """Kind ``time``: sensors, wheel powers and states, one shared time axis."""
    from matplotlib.patches import Patch

    replay = run.replay
    times = replay.times
    specs = {s.port: s for s in replay.sensors}
    series = sensor_series(replay)
    distance = [p for p in series if specs.get(p) is None or specs[p].kind == "distance"]
    touch = [p for p in series if specs.get(p) is not None and specs[p].kind == "touch"]
    rows = [3.0] + ([1.0] if touch else []) + [2.0, 0.8]
    axes = fig.subplots(len(rows), 1, sharex=True, gridspec_kw={"height_ratios": rows})
    ax_dist = axes[0]
    for port in distance:
        mount = specs[port].mount if port in specs else "?"
        ax_dist.plot(
            times, series[port], linewidth=1, label=f"port {port} ({mount})", gid=f"sensor-{port}"
        )
    ax_dist.set_ylabel(f"distance ({run.profile.unit})")
    if distance:
        ax_dist.legend(loc="upper right", fontsize=7, ncol=min(4, len(distance)))
    else:
        ax_dist.text(0.5, 0.5, "no distance sensor", ha="center", transform=ax_dist.transAxes)
    at = 1
    if touch:
        ax_touch = axes[at]
        for port in touch:
            ax_touch.step(
                times,
                series[port],
                where="post",
                linewidth=1,
                label=f"port {port} ({specs[port].mount})",
                gid=f"sensor-{port}",
            )
        ax_touch.set_ylim(-0.2, 1.2)
        ax_touch.set_yticks([0, 1])
        ax_touch.set_ylabel("touch")
        ax_touch.legend(loc="upper right", fontsize=7, ncol=min(4, len(touch)))
        at += 1
    ax_power = axes[at]
    wheels = powers(replay)
    ax_power.step(times, wheels.left, where="post", linewidth=1, label="left", gid="power-left")
    ax_power.step(times, wheels.right, where="post", linewidth=1, label="right", gid="power-right")
    for t, _degrees in wheels.turns:
        ax_power.axvline(t, color="#9467bd", linewidth=0.6, alpha=0.6)
    if wheels.turns:
        ax_power.plot(
            [t for t, _ in wheels.turns],
            [1.1] * len(wheels.turns),
            linestyle="none",
            marker="v",
            color="#9467bd",
            markersize=4,
            gid="turn-commands",
            label=f"turn by degrees ({len(wheels.turns)})",
        )
    collisions = [times[i] for i in event_ticks(replay, "collision")]
    if collisions:
        ax_power.plot(
            collisions,
            [-1.1] * len(collisions),
            linestyle="none",
            marker="X",
            color="#d62728",
            markersize=5,
            gid="collisions",
            label=f"collision ({len(collisions)})",
        )
    ax_power.set_ylim(-1.25, 1.25)
    ax_power.set_ylabel("wheel power")
    ax_power.legend(loc="lower right", fontsize=7, ncol=4)
    if wheels.turns:
        ax_power.set_title("a gap: turning by degrees", fontsize=7, loc="left")
    ax_band = axes[at + 1]
    spans = state_spans(replay)
    names = sorted({s.state for s in spans})
    if spans:
        from matplotlib.colors import ListedColormap

        colours = [f"C{k % 10}" for k in range(len(names))]
        start, end = times[0], max(times[-1], times[0] + 1e-9)
        starts = [s.start for s in spans]
        index = {name: k for k, name in enumerate(names)}
        columns = []
        for j in range(BAND_COLUMNS):
            t = start + (j + 0.5) * (end - start) / BAND_COLUMNS
            span = spans[max(0, bisect.bisect_right(starts, t) - 1)]
            columns.append(index[span.state])
        ax_band.imshow(
            [columns],
            aspect="auto",
            extent=(start, end, 0, 1),
            interpolation="nearest",
            cmap=ListedColormap(colours),
            vmin=-0.5,
            vmax=len(names) - 0.5,
            gid="state-band",
        )
        shown = names[:LEGEND_STATES]
        handles = [Patch(color=colours[index[n]], label=n) for n in shown]
        if len(names) > LEGEND_STATES:
            handles.append(Patch(color="white", label=f"and {len(names) - LEGEND_STATES} more"))
        ax_band.legend(
            handles=handles,
            loc="upper center",
            bbox_to_anchor=(0.5, -0.75),
            ncol=min(4, len(handles)),
            fontsize=7,
            frameon=False,
        )
    else:
        ax_band.text(
            0.5,
            0.5,
            "no controller: nothing recorded",
            ha="center",
            va="center",
            transform=ax_band.transAxes,
            fontsize=8,
        )
    ax_band.set_yticks([])
    ax_band.set_ylabel(band_title(replay.driver), rotation=0, ha="right", va="center")
    ax_band.set_xlabel("time (s)")
    ax_band.set_xlim(times[0], max(times[-1], times[0] + 1e-9))
    stop = record_stop(run)
    title = f"{heading(run)}\n" + " | ".join(figure_lines(run))
    fig.suptitle(title if stop is None else f"{title}\n{stop}", fontsize=9)
