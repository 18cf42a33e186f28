"""The main screen's compositor: every partial update leaves the screen as a full render draws it.

The updates the app sends while the robot drives are applied, one by one, to a grid of cells
(character and style) the way a terminal applies them. Every cell an update writes must be the
cell a full render of the screen draws at that moment, and once the screen is still the whole
grid must equal a full render. (Cells an update does not write may lag a frame behind: a widget
whose text changed is rendered by the next update, once the screen has marked it dirty.) And a
redraw of a snapshot that did not change refreshes nothing at all.
"""

from __future__ import annotations

import pytest
from rich.cells import cell_len
from rich.segment import ControlType, Segment
from rich.style import Style
from textual.geometry import Region
from textual.pilot import Pilot
from textual.strip import Strip
from textual.widget import Widget

from tests.app.support import run
from tests.waiting import until
from workbench.tui.app import WorkbenchApp, make_app
from workbench.tui.screens.main import MainScreen
from workbench.tui.serving.compositor import GroupedUpdate, LiveCompositor, merged_crops
from workbench.tui.widgets.log_scroll_bar import LogScrollBar
from workbench.tui.widgets.maze_view import MazeView
from workbench.tui.widgets.transition_log import TransitionLog
from workbench.wire.settings import AppSettings

Cell = tuple[str, Style | None]


def cells(strips: list[Strip], width: int) -> list[list[Cell]]:
    grid = []
    for strip in strips:
        row: list[Cell] = []
        for segment in strip:
            for char in segment.text:
                row.extend([(char, segment.style)] * max(cell_len(char), 1))
        grid.append((row + [(" ", None)] * width)[:width])
    return grid


def apply(grid: list[list[Cell]], segments: list[Segment]) -> None:
    """Write an update's segments on ``grid`` as a terminal would (cursor moves and text)."""
    x = y = 0
    for segment in segments:
        if segment.control:
            for code in segment.control:
                if code[0] == ControlType.CURSOR_MOVE_TO:
                    x, y = code[1], code[2]
            continue
        if segment.text == "\n":
            continue
        for char in segment.text:
            grid[y][x] = (char, segment.style)
            x += max(cell_len(char), 1)


class Checker:
    """Applies each partial update of ``screen`` to a grid and compares it with a full render."""

    def __init__(self, app: WorkbenchApp, screen: MainScreen) -> None:
        self.app = app
        self.compositor = screen._compositor
        assert isinstance(self.compositor, LiveCompositor)
        self.width = self.compositor.size.width
        self.grid = cells(self.compositor.render_strips(), self.width)
        self.updates = 0
        self.grouped = 0
        self.full = 0
        self.mismatches: list[str] = []
        partial = self.compositor.render_partial_update

        def checked():
            update = partial()
            if update is not None:
                self.check(update)
            return update

        self.compositor.render_partial_update = checked  # type: ignore[method-assign]
        full_update = self.compositor.render_full_update

        def repainted(simplify: bool = False):
            # a full update (a layout change, say) repaints every cell: the terminal shows a
            # full render from here on, so that is what the next partial update builds on
            update = full_update(simplify=simplify)
            self.grid = cells(self.compositor.render_strips(), self.width)
            self.full += 1
            return update

        self.compositor.render_full_update = repainted  # type: ignore[method-assign]

    def check(self, update) -> None:
        console = self.app.console
        self.updates += 1
        self.grouped += isinstance(update, GroupedUpdate)
        apply(self.grid, list(update.__rich_console__(console, console.options)))
        full = cells(self.compositor.render_strips(), self.width)
        parts = update.updates if isinstance(update, GroupedUpdate) else [update]
        for y, x1, x2 in sorted({span for part in parts for span in part.spans}):
            if self.grid[y][x1:x2] != full[y][x1:x2]:
                text = "".join(c for c, _ in self.grid[y][x1:x2])
                self.mismatches.append(f"update {self.updates}, line {y} [{x1}:{x2}]: {text!r}")
                self.grid[y][x1:x2] = full[y][x1:x2]  # report each difference once

    def settled(self) -> list[str]:
        """The lines where the screen, once still, differs from a full render."""
        full = cells(self.compositor.render_strips(), self.width)
        return [
            f"line {y}: {''.join(c for c, _ in got)!r}"
            for y, (got, want) in enumerate(zip(self.grid, full, strict=True))
            if got != want
        ]


@pytest.mark.parametrize("size", [(80, 24), (120, 40)])
def test_partial_updates_match_a_full_render_while_the_robot_drives(size):
    app = make_app(AppSettings(noise="off"))

    async def body(pilot: Pilot) -> None:
        screen = app.screen
        assert isinstance(screen, MainScreen)
        checker = Checker(app, screen)

        def moved_on(drawn: int):
            return lambda: checker.updates >= drawn + 3 or app._resting

        await pilot.press("w")
        for keys in ("", "d", "", "u", "a", "t", "", "p", "n", "p", "a", "u", "", "d"):
            for key in keys:
                await pilot.press(key)
            # the robot drives on for a few frames (later on a busy machine), unless the app
            # is at rest (paused, or nothing moves): then there is nothing new to draw
            await until(moved_on(checker.updates), "three more updates, or the app at rest")
        await pilot.pause()
        assert checker.mismatches == []
        if not app.station.pacer.paused:
            await pilot.press("p")  # still: every change reaches the screen
        await until(lambda: checker.settled() == [], "the still screen drawn whole")
        assert checker.mismatches == []
        assert checker.updates >= 20
        assert checker.grouped >= 1  # the maze and a panel changed in the same frame

    run(app, body, size=size)


def test_redrawing_an_unchanged_snapshot_refreshes_nothing():
    app = make_app(AppSettings(noise="off", paused=True))

    async def body(pilot: Pilot) -> None:
        screen = app.screen
        assert isinstance(screen, MainScreen)
        await pilot.press("w")
        app.station.step(30)
        app.refresh_views()
        await pilot.pause()
        view = screen.query_one(MazeView)
        built = view.strips_built
        screen._panels_at = 0.0  # the panels are due as well
        app.refresh_views()
        assert not screen._dirty_widgets
        assert not screen._compositor._dirty_regions
        assert view.strips_built == built

    run(app, body)


def test_groups_of_changes_whose_boxes_overlap_are_rendered_as_one():
    log = [Region(40, 10, 30, 5)]
    bar = [Region(69, 12, 1, 3)]
    apart = [Region(0, 0, 10, 1)]
    within = [Region(41, 14, 5, 2)]  # overlaps the log's box, reaching below it
    crops = sorted(merged_crops([log, apart, bar, within]))
    assert crops[0] == (Region(0, 0, 10, 1), apart)
    crop, regions = crops[1]
    assert crop == Region(40, 10, 30, 6)
    assert sorted(regions) == sorted(log + bar + within)


def test_no_widget_is_rendered_twice_for_one_update_while_an_algorithm_runs(monkeypatch):
    # a new transition changes the log and its scroll bar (whose column is inside the log's
    # box): rendered as one box, each of them once
    app = make_app(AppSettings(noise="off"))
    rendered: list[Widget] = []
    depth = [0]  # a widget drawn Textual's way from its own render_lines is one render

    def counting(render_lines):
        def counted(widget: Widget, crop: Region) -> list[Strip]:
            if not depth[0]:
                rendered.append(widget)
            depth[0] += 1
            try:
                return render_lines(widget, crop)
            finally:
                depth[0] -= 1

        return counted

    # the widgets that draw their own lines, and every other
    for cls in (Widget, MazeView, TransitionLog, LogScrollBar):
        monkeypatch.setattr(cls, "render_lines", counting(vars(cls)["render_lines"]))

    async def body(pilot: Pilot) -> None:
        screen = app.screen
        assert isinstance(screen, MainScreen)
        compositor = screen._compositor
        partial = compositor.render_partial_update
        twice: list[str] = []
        logged: list[int] = []

        def checked():
            rendered.clear()
            update = partial()
            log = screen.query_one(TransitionLog)
            if log in rendered:
                logged.append(len(rendered))
            twice.extend(repr(w) for w in set(rendered) if rendered.count(w) > 1)
            return update

        compositor.render_partial_update = checked  # type: ignore[method-assign]
        station = app.station
        station.select_algorithm("right-wall")
        station.apply_algorithm_preset()
        await pilot.pause()
        station.start()
        await until(lambda: len(logged) >= 4, "four updates that drew the transition log")
        assert twice == []

    run(app, body)
