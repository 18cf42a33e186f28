"""What the runs screen's table shows: which runs (this maze's or every maze's), which columns
fit the width, and the chosen run in words with the measures the table had no room for.

The graded measures (out or not, time, distance, turning, turns, collisions) always stand,
whatever the width: where they and the names do not all fit, the names (driver, maze,
profile) are shortened, and the columns that are no measure (efficiency, how the run ended,
its record) give way. The detail line under the table says the chosen run whole."""

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

#: the columns a table always keeps whole, whatever the width: the run and its graded measures
KEPT = ("number", "reached", "time", "distance", "turning", "turns", "contacts")
#: the columns of names, always kept but shortened where the width is short
NAMES = ("driver", "maze", "profile")
#: the fewest characters a shortened name keeps (its mark included)
SHORTEST_NAME = 4


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


def _driver(run: RunEntry) -> str:
    """Who drove, as short as says it: an algorithm's name, a program file's name."""
    driver = run.driver
    return driver.name if driver.kind == "program" and driver.digest else driver.short


def _yes_no(value: bool, unicode: bool) -> str:
    return ("✓" if value else "✗") if unicode else ("yes" if value else "no")


#: every column, in the order they stand in the table
COLUMNS: tuple[RunColumn, ...] = (
    RunColumn("number", "#", "#", lambda r, u: str(r.number), 0, True),
    RunColumn("driver", "Driver", "Driver", lambda r, u: _driver(r), 0, True),
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


def one_profile(runs: Sequence[RunEntry]) -> str:
    """The profile every run in ``runs`` was made with ("" when they differ or none are)."""
    profiles = {r.profile for r in runs}
    return profiles.pop() if len(profiles) == 1 else ""


def scope_columns(runs: Sequence[RunEntry], scope: str) -> set[str]:
    """The columns a scope shows: the maze only where runs on several mazes are, and the
    profile only where they were made with more than one (the title names a single one)."""
    keys = {c.key for c in COLUMNS}
    if scope != ALL_MAZES:
        return keys - {"maze", "profile"}
    return keys - ({"profile"} if one_profile(runs) else set())


def shorten(text: str, width: int, unicode: bool) -> str:
    """``text`` cut to ``width`` cells, with a mark (``…``, ``~`` in ASCII) where it was cut."""
    if cell_len(text) <= width:
        return text
    mark = "…" if unicode else "~"
    return text[: max(0, width - 1)] + mark


@dataclass(frozen=True)
class FittedColumns:
    """The columns that fit, in table order, and how wide the name columns' cells may be."""

    columns: tuple[RunColumn, ...]
    #: the widest a name column's cells may be (by key); longer names are shortened
    name_widths: dict[str, int]

    def cells(self, run: RunEntry, unicode: bool) -> tuple[str, ...]:
        """A run's cells in these columns (its names shortened to fit)."""
        out = []
        for column in self.columns:
            text = column.cell(run, unicode)
            if column.key in self.name_widths:
                text = shorten(text, self.name_widths[column.key], unicode)
            out.append(text)
        return tuple(out)

    @property
    def keys(self) -> tuple[str, ...]:
        return tuple(c.key for c in self.columns)


def _widest(column: RunColumn, runs: Sequence[RunEntry], unicode: bool) -> int:
    return max(
        cell_len(s) for s in [heading(column, unicode), *(column.cell(r, unicode) for r in runs)]
    )


def fit_columns(
    runs: Sequence[RunEntry], unicode: bool, width: int, scope: str, padding: int = 1
) -> FittedColumns:
    """The columns that fit ``width`` cells, in table order, each as wide as its widest cell
    or heading plus ``padding`` on each side: the run's number and its graded measures
    always; the names (driver; maze, and profile where they differ, where runs on several
    mazes are shown) whole where they fit, else shortened (the longest first, never below
    their heading or :data:`SHORTEST_NAME`); then the other columns, the lowest ranks
    first, while they fit."""
    wanted = [c for c in COLUMNS if c.key in scope_columns(runs, scope)]
    widest = {c.key: _widest(c, runs, unicode) for c in wanted}
    used = sum(widest[key] + 2 * padding for key in KEPT)
    names = {c.key: widest[c.key] for c in wanted if c.key in NAMES}
    least = {key: max(SHORTEST_NAME, cell_len(heading(BY_KEY[key], unicode))) for key in names}
    room = width - used - 2 * padding * len(names)
    while sum(names.values()) > room:
        key = max(names, key=lambda k: (names[k] - least[k], names[k]))
        if names[key] <= least[key]:
            break
        names[key] -= 1
    used += sum(names.values()) + 2 * padding * len(names)
    chosen = set(KEPT) | set(names)
    rest = sorted((c for c in wanted if c.key not in chosen), key=lambda c: c.rank)
    for column in rest:
        needed = widest[column.key] + 2 * padding
        if used + needed <= width:
            chosen.add(column.key)
            used += needed
    shortened = {key: w for key, w in names.items() if w < widest[key]}
    return FittedColumns(tuple(c for c in wanted if c.key in chosen), shortened)


def run_detail(run: RunEntry, hidden: Sequence[RunColumn] = (), unicode: bool = False) -> str:
    """The chosen run in words, whole: who drove (the name whole, where the table shortened
    it), on which maze and profile, its collisions and touches, its record, and the measures
    of the ``hidden`` columns."""
    m = run.metrics
    record = f"record {Path(run.record).name}" if run.record else "not recorded"
    words = (
        f"run {run.number}: {run.driver} on {run.maze or '-'} ({run.profile}, seed {run.seed}), "
        f"ended by {run.ended}; {count(m.collisions, 'collision')}, "
        f"{count(m.touches, 'touch', 'touches')}; {record}"
    )
    rest = [f"{heading(c, unicode)} {c.cell(run, unicode)}" for c in hidden if not c.in_words]
    return f"{words}; {', '.join(rest)}" if rest else words
