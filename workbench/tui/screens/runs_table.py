"""What the runs screen's table shows: which runs (this maze's or every maze's), which columns
fit the width, and the chosen run in words with the measures the table had no room for."""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path

from rich.cells import cell_len

from workbench.control.station import RunEntry
from workbench.sim.metrics import Metrics

from ..widgets.text import count

#: the runs shown: those on the station's maze with its profile, or every run
THIS_MAZE = "this maze"
ALL_MAZES = "all mazes"
SCOPES = (THIS_MAZE, ALL_MAZES)

#: the columns a table always keeps, whatever the width
NARROWEST = ("number", "driver")


def _time(m: Metrics) -> float:
    return m.exit_time if m.reached_exit and m.exit_time is not None else m.sim_time


@dataclass(frozen=True)
class RunColumn:
    """One column of the runs table: its key, headings, the cell of a run, and its rank where
    not every column fits (lower ranks stay longest)."""

    key: str
    ascii: str
    unicode: str
    cell: Callable[[RunEntry, bool], str]
    rank: int
    #: whether the detail line's words already say it (else it is listed there when hidden)
    in_words: bool = False


def _yes_no(value: bool, unicode: bool) -> str:
    return ("✓" if value else "✗") if unicode else ("yes" if value else "no")


#: every column, in the order they stand in the table
COLUMNS: tuple[RunColumn, ...] = (
    RunColumn("number", "#", "#", lambda r, u: str(r.number), 0, True),
    RunColumn("driver", "Driver", "Driver", lambda r, u: r.driver.short, 0, True),
    RunColumn("maze", "Maze", "Maze", lambda r, u: r.maze or "-", 9, True),
    RunColumn("profile", "Profile", "Profile", lambda r, u: r.profile, 10, True),
    RunColumn("reached", "Out", "Out", lambda r, u: _yes_no(r.metrics.reached_exit, u), 1),
    RunColumn("time", "Time s", "Time s", lambda r, u: f"{_time(r.metrics):.1f}", 2),
    RunColumn("distance", "Blocks", "Blocks", lambda r, u: f"{r.metrics.distance_cells:.2f}", 3),
    RunColumn("turning", "Turn deg", "Turn °", lambda r, u: f"{r.metrics.turn_degrees:.0f}", 7),
    RunColumn("turns", "Turns", "Turns", lambda r, u: str(r.metrics.turns), 5),
    RunColumn(
        "contacts",
        "Hit/Tch",
        "Hit/Tch",
        lambda r, u: f"{r.metrics.collisions}/{r.metrics.touches}",
        4,
        True,
    ),
    RunColumn(
        "efficiency",
        "Eff",
        "Eff",
        lambda r, u: f"{r.metrics.efficiency:.2f}" if r.metrics.efficiency is not None else "-",
        6,
    ),
    RunColumn("ended", "Ended", "Ended", lambda r, u: r.ended, 8, True),
    RunColumn("record", "Rec", "Rec", lambda r, u: _yes_no(True, u) if r.record else "-", 11, True),
)
BY_KEY = {column.key: column for column in COLUMNS}


def heading(column: RunColumn, unicode: bool) -> str:
    return column.unicode if unicode else column.ascii


def runs_in_scope(
    runs: Sequence[RunEntry], scope: str, maze_digest: str, profile: str
) -> list[RunEntry]:
    """The runs a scope shows: on this maze (same layout) with this profile, in the order they
    ran; or every run, grouped by maze and profile."""
    if scope == THIS_MAZE:
        return [r for r in runs if r.maze_digest == maze_digest and r.profile == profile]
    return sorted(runs, key=lambda r: (r.maze, r.profile, r.number))


def fit_columns(
    runs: Sequence[RunEntry], unicode: bool, width: int, scope: str, padding: int = 1
) -> tuple[RunColumn, ...]:
    """The columns that fit ``width`` cells whole, in table order: the lowest ranks first,
    each column as wide as its widest cell or heading plus ``padding`` on each side. The
    maze and profile columns only stand where runs on several mazes are shown."""
    wanted = [c for c in COLUMNS if scope == ALL_MAZES or c.key not in ("maze", "profile")]
    if scope == ALL_MAZES:  # which maze a run was on matters more than its measures
        order = sorted(wanted, key=lambda c: c.rank if c.key not in ("maze", "profile") else 0.5)
    else:
        order = sorted(wanted, key=lambda c: c.rank)
    chosen: set[str] = set()
    used = 0
    for column in order:
        cells = [column.cell(run, unicode) for run in runs]
        needed = max(cell_len(s) for s in [heading(column, unicode), *cells]) + 2 * padding
        if column.key in NARROWEST or used + needed <= width:
            chosen.add(column.key)
            used += needed
    return tuple(c for c in COLUMNS if c.key in chosen)


def run_detail(run: RunEntry, hidden: Sequence[RunColumn] = (), unicode: bool = False) -> str:
    """The chosen run in words, whole: who drove, on which maze and profile, its collisions
    and touches, its record, and the measures of the ``hidden`` columns."""
    m = run.metrics
    record = f"record {Path(run.record).name}" if run.record else "not recorded"
    words = (
        f"run {run.number}: {run.driver} on {run.maze or '-'} ({run.profile}, seed {run.seed}), "
        f"ended by {run.ended}; {count(m.collisions, 'collision')}, "
        f"{count(m.touches, 'touch', 'touches')}; {record}"
    )
    rest = [f"{heading(c, unicode)} {c.cell(run, unicode)}" for c in hidden if not c.in_words]
    return f"{words}; {', '.join(rest)}" if rest else words
