"""The runs screen: the station's last runs side by side, and the way into their replays.

Each row is one run with the course's measures, so students can answer "which algorithm is
better on this maze": it shows the runs on the station's maze and profile, and ``a`` shows the
runs on every maze, grouped by maze and profile. The table always keeps the graded measures,
shortening long names to fit the width; the line under it says the chosen run whole. Enter
(or a click) on a run with a record opens its replay; ``o`` opens any run record by path.
``p``, ``t`` and ``c`` save pictures of the chosen run (its path, its plot over time) or of the
recorded runs on this maze side by side in the workspace's ``pictures/`` folder.
"""

from __future__ import annotations

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
from ..picture_saving import save_picture_off_the_loop
from ..serving.single_layout import SingleLayout
from ..widgets.key_bar import KeyBar
from .replay import ReplayScreen
from .runs_table import (
    ALL_MAZES,
    COLUMNS,
    SCOPES,
    THIS_MAZE,
    RunColumn,
    fit_columns,
    heading,
    one_profile,
    run_detail,
    runs_in_scope,
)

OPEN_HELP = (
    "A run record is a .jsonl file written by 'workbench run --record FILE' or by the app "
    "when it records runs."
)


class RunsScreen(ShowsSnapshot, FollowsUnicode, SingleLayout, Screen[None]):
    """The station's runs side by side; enter replays one, ``o`` opens a record file."""

    DEFAULT_CSS = """
    RunsScreen #runs-title {
        height: auto;
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
        self._shown: tuple[object, ...] | None = None
        self._shown_count = -1
        #: which runs the table shows: :data:`THIS_MAZE` or :data:`ALL_MAZES`
        self.scope = THIS_MAZE
        self._runs: list[RunEntry] = []
        #: the runs the scope shows now (the title names their profile when they share one)
        self._in_scope: list[RunEntry] = []
        self._columns: tuple[RunColumn, ...] = COLUMNS
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

    def on_resize(self) -> None:
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
        """Show the runs in scope (in the order they ran, or grouped by maze and profile) with
        the columns that fit; repaints only when they changed."""
        station = self.station
        self._shown_count = len(station.runs)
        runs = runs_in_scope(station.runs, self.scope, station.maze.digest(), station.profile)
        table = self.query_one(DataTable)
        scrollbar = table.styles.scrollbar_size_vertical
        width = (self.size.width or self.app.size.width) - scrollbar
        self._in_scope = runs
        fitted = fit_columns(runs, self.unicode, width, self.scope, table.cell_padding)
        columns = fitted.columns
        self.query_one("#runs-title", Static).update(self._title(len(runs)))
        self.query_one("#runs-help", Static).update(self._help(runs))
        rows = tuple(fitted.cells(run, self.unicode) for run in runs)
        shown = (self.scope, self.unicode, fitted.keys, rows)
        if shown == self._shown:
            return
        self._shown = shown
        self._runs = runs
        self._columns = columns
        row = table.cursor_row
        table.clear(columns=True)
        for column in columns:
            table.add_column(heading(column, self.unicode), key=column.key)
        for run, cells in zip(runs, rows, strict=True):
            table.add_row(*cells, key=str(run.number))
        if runs:
            table.move_cursor(row=min(max(row, 0), len(runs) - 1))
        self._show_detail()

    def _title(self, shown: int) -> str:
        station = self.station
        total = len(station.runs)
        if self.scope == ALL_MAZES:
            profile = one_profile(self._in_scope)
            grouped = f"all {profile}, by maze" if profile else "by maze and profile"
            return f"Runs on every maze: {total}, {grouped}  (a: this maze only)"
        where = f"{station.maze.name or '-'} ({station.profile})"
        others = total - shown
        more = f", {others} on other mazes (a shows all)" if others else ""
        return f"Runs on {where}: {shown}{more}"

    def _help(self, runs: list[RunEntry]) -> str:
        if runs:
            return (
                "Hit/Tch = collisions/touch-sensor bumps. "
                "Enter replays a recorded run; o opens a record file; p saves its picture."
            )
        if self.station.runs:
            return "No runs on this maze yet: a shows the runs on other mazes."
        return (
            "No runs yet: drive with the keys or start an algorithm, then come back. "
            "o opens a record file."
        )

    def action_scope(self) -> None:
        """Show the runs on this maze only, or on every maze."""
        self.scope = SCOPES[(SCOPES.index(self.scope) + 1) % len(SCOPES)]
        self.refresh_runs()

    def _show_detail(self) -> None:
        run = self._selected()
        hidden = [c for c in COLUMNS if c not in self._columns]
        text = run_detail(run, hidden, self.unicode) if run else ""
        self.query_one("#runs-detail", Static).update(text)

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
        if not self._runs or table.row_count == 0:
            return None
        key = table.coordinate_to_cell_key(table.cursor_coordinate).row_key.value
        return next((r for r in self._runs if str(r.number) == key), None)

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

    # -- pictures ----------------------------------------------------------------------------
    def action_picture(self, kind: str) -> None:
        """Save a picture: the chosen run's (``path``, ``time``) or this maze's recorded runs
        side by side (``compare``), drawn in a thread."""
        if kind == "compare":
            digest = self.station.maze.digest()
            runs = [r for r in self.station.runs if r.record and r.maze_digest == digest][-12:]
            if not runs:
                self._status("no recorded run on this maze to put side by side", error=True)
                return
            what = f"{len(runs)} run{'' if len(runs) == 1 else 's'} on this maze"
        else:
            run = self._selected()
            if run is None:
                self._status("no run to draw yet", error=True)
                return
            if run.record is None:
                self._status(
                    f"run {run.number} was not recorded: start the workbench with a record "
                    "folder to draw runs",
                    error=True,
                )
                return
            runs, what = [run], f"run {run.number}"
        save_picture_off_the_loop(
            self,
            [str(r.record) for r in runs],
            kind,
            self.station.files,
            self._status,
            what=what,
            known=(self.station.maze,),
        )

    def action_unicode(self) -> None:
        self.post_message(ToggleUnicode())

    def action_leave(self) -> None:
        if len(self.app.screen_stack) > 1 and self.app.screen is self:
            self.dismiss(None)
        else:
            self.app.exit()
