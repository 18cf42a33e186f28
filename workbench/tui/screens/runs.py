"""The runs screen: the station's last runs side by side, and the way into their replays.

Each row is one run with the course's measures, so students can answer "which algorithm is
better on this maze". Enter (or a click) on a run with a record opens its replay; ``o`` opens
any run record (JSONL) by path.
"""

from __future__ import annotations

from pathlib import Path
from typing import ClassVar

from textual import on
from textual.app import ComposeResult
from textual.binding import BindingType
from textual.screen import Screen
from textual.widgets import DataTable, Static

from workbench.control.station import LabStation, RunEntry
from workbench.files.workspace import OutsideWorkspace
from workbench.sim.record import RecordError
from workbench.sim.replay import load_replay
from workbench.sim.session import Snapshot

from ..dialogs.path import PathDialog
from ..host import FollowsUnicode, ShowsSnapshot, ToggleUnicode
from ..keys import RUNS_KEY_IDS, bindings
from ..widgets.key_bar import KeyBar
from ..widgets.text import count
from .replay import ReplayScreen

#: column key, heading (ASCII), heading (Unicode)
COLUMNS: tuple[tuple[str, str, str], ...] = (
    ("number", "#", "#"),
    ("driver", "Driver", "Driver"),
    ("reached", "Out", "Out"),
    ("time", "Time s", "Time s"),
    ("distance", "Blocks", "Blocks"),
    ("turning", "Turn deg", "Turn °"),
    ("turns", "Turns", "Turns"),
    ("contacts", "Hit/Tch", "Hit/Tch"),
    ("efficiency", "Eff", "Eff"),
    ("ended", "Ended", "Ended"),
    ("record", "Rec", "Rec"),
    ("maze", "Maze", "Maze"),
)
OPEN_HELP = (
    "A run record is a .jsonl file written by 'workbench run --record FILE' or by the app "
    "when it records runs."
)


def run_cells(run: RunEntry, unicode: bool) -> tuple[str, ...]:
    """The table cells of a run, in :data:`COLUMNS` order."""
    m = run.metrics
    time = m.exit_time if m.reached_exit and m.exit_time is not None else m.sim_time
    yes, no = ("✓", "✗") if unicode else ("yes", "no")
    return (
        str(run.number),
        run.driver.short,
        yes if m.reached_exit else no,
        f"{time:.1f}",
        f"{m.distance_cells:.2f}",
        f"{m.turn_degrees:.0f}",
        str(m.turns),
        f"{m.collisions}/{m.touches}",
        f"{m.efficiency:.2f}" if m.efficiency is not None else "-",
        run.ended,
        yes if run.record else "-",
        run.maze or "-",
    )


def run_detail(run: RunEntry) -> str:
    """The chosen run in words, whole: who drove, on which maze and profile, its collisions
    and touches, its record (the table's last columns do not fit 80 columns)."""
    m = run.metrics
    record = f"record {Path(run.record).name}" if run.record else "not recorded"
    return (
        f"run {run.number}: {run.driver} on {run.maze or '-'} ({run.profile}, seed {run.seed}), "
        f"ended by {run.ended}; {count(m.collisions, 'collision')}, "
        f"{count(m.touches, 'touch', 'touches')}; {record}"
    )


class RunsScreen(ShowsSnapshot, FollowsUnicode, Screen[None]):
    """The station's runs side by side; enter replays one, ``o`` opens a record file."""

    DEFAULT_CSS = """
    RunsScreen #runs-title {
        height: 1;
        padding: 0 1;
        background: $boost;
        text-style: bold;
    }
    RunsScreen #runs-help {
        height: auto;
        padding: 0 1;
        color: $text-muted;
    }
    RunsScreen #runs-table {
        height: 1fr;
    }
    RunsScreen #runs-detail {
        height: auto;
        padding: 0 1;
    }
    RunsScreen #runs-status {
        height: auto;
        padding: 0 1;
        color: $text-muted;
    }
    RunsScreen #runs-status.-error {
        color: $text-error;
    }
    """

    BINDINGS: ClassVar[list[BindingType]] = [*bindings(*RUNS_KEY_IDS)]

    def __init__(
        self,
        station: LabStation,
        unicode: bool = False,
        *,
        name: str | None = None,
        id: str | None = None,
        classes: str | None = None,
    ) -> None:
        super().__init__(name=name, id=id, classes=classes)
        self.station = station
        self._unicode = unicode
        self._shown: tuple[tuple[str, ...], ...] | None = None
        self._shown_count = -1
        #: the last message shown under the table (what happened, or why not)
        self.status = ""

    def compose(self) -> ComposeResult:
        yield Static(id="runs-title", markup=False)
        yield Static(id="runs-help", markup=False)
        yield DataTable(id="runs-table", cursor_type="row", zebra_stripes=True)
        yield Static(id="runs-detail", markup=False)
        yield Static(id="runs-status", markup=False)
        yield KeyBar()

    def on_mount(self) -> None:
        self.refresh_runs()

    def on_screen_resume(self) -> None:
        self.refresh_runs()

    # -- public ------------------------------------------------------------------------------
    @property
    def unicode(self) -> bool:
        return self._unicode

    def set_unicode(self, unicode: bool) -> None:
        self._unicode = unicode
        if self.is_mounted:
            self._shown = None
            self.refresh_runs()

    def show_snapshot(self, snapshot: Snapshot) -> None:
        """Called by the app on every frame: pick up runs that ended meanwhile."""
        if len(self.station.runs) != self._shown_count:
            self.refresh_runs()

    def refresh_runs(self) -> None:
        """Show the station's runs (newest last); repaints only when they changed."""
        runs = self.station.runs
        self._shown_count = len(runs)
        rows = tuple(run_cells(run, self.unicode) for run in runs)
        table = self.query_one(DataTable)
        self.query_one("#runs-title", Static).update(
            f"Runs on this bench: {len(runs)}  [maze now: {self.station.maze.name or '-'}]"
        )
        if runs:
            help_text = (
                "Compare runs on one maze; Hit/Tch = collisions/touch-sensor bumps. "
                "Enter replays a recorded run; o opens a record file."
            )
        else:
            help_text = (
                "No runs yet: drive with the keys or start an algorithm, then come back. "
                "o opens a record file."
            )
        self.query_one("#runs-help", Static).update(help_text)
        if rows == self._shown:
            return
        self._shown = rows
        row = table.cursor_row
        table.clear(columns=True)
        for key, ascii_label, unicode_label in COLUMNS:
            table.add_column(unicode_label if self.unicode else ascii_label, key=key)
        for run, cells in zip(runs, rows, strict=True):
            table.add_row(*cells, key=str(run.number))
        if runs:
            table.move_cursor(row=min(max(row, 0), len(runs) - 1))
        self._show_detail()

    def _show_detail(self) -> None:
        run = self._selected()
        self.query_one("#runs-detail", Static).update(run_detail(run) if run else "")

    @on(DataTable.RowHighlighted, "#runs-table")
    def _row_highlighted(self, event: DataTable.RowHighlighted) -> None:
        event.stop()
        self._show_detail()

    # -- status ------------------------------------------------------------------------------
    def _status(self, text: str, error: bool = False) -> None:
        self.status = text
        status = self.query_one("#runs-status", Static)
        status.update(text)
        status.set_class(error, "-error")

    # -- replay ------------------------------------------------------------------------------
    def _selected(self) -> RunEntry | None:
        table = self.query_one(DataTable)
        if not self.station.runs or table.row_count == 0:
            return None
        key = table.coordinate_to_cell_key(table.cursor_coordinate).row_key.value
        return next((r for r in self.station.runs if str(r.number) == key), None)

    def action_replay(self) -> None:
        run = self._selected()
        if run is None:
            self._status("no run to replay yet", error=True)
            return
        if run.record is None:
            self._status(
                f"run {run.number} was not recorded: start the workbench with a record folder "
                "to replay runs",
                error=True,
            )
            return
        self.open_record(run.record)

    @on(DataTable.RowSelected, "#runs-table")
    def _row_selected(self, event: DataTable.RowSelected) -> None:
        event.stop()
        self.action_replay()

    def open_record(self, path: str) -> bool:
        """Open the replay of the record at ``path``; a bad record is reported here."""
        try:
            real = self.station.files.for_reading(path)
            replay = load_replay(real)
            screen = ReplayScreen(
                real,
                replay,
                mazes=(self.station.maze,),
                unicode=self.unicode,
                files=self.station.files,
            )
        except (OutsideWorkspace, RecordError) as exc:
            self._status(str(exc), error=True)
            return False
        self._status("")
        self.app.push_screen(screen)
        return True

    def action_open(self, error: str = "", value: str = "") -> None:
        def chosen(path: str | None) -> None:
            if path is None:
                return
            if not self.open_record(path):
                self.action_open(self.status, path)

        self.app.push_screen(
            PathDialog(
                "Open a run record",
                OPEN_HELP,
                value=value or self.station.files.home(),
                action="Open",
                error=error,
                note=self.station.files.note(),
            ),
            chosen,
        )

    def action_unicode(self) -> None:
        self.post_message(ToggleUnicode())

    def action_leave(self) -> None:
        if len(self.app.screen_stack) > 1 and self.app.screen is self:
            self.dismiss(None)
        else:
            self.app.exit()
