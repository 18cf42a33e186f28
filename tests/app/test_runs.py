"""The runs screen and the replay screen, driven through a tiny host app with App.run_test()."""

from __future__ import annotations

import json
from dataclasses import replace

import pytest
from textual.widgets import DataTable, Input, Static

from tests.app.runs_support import BEND, run_algorithms, runs_with_long_driver_names
from tests.app.support import Host, screen_lines, sync
from workbench.control.station import LabStation
from workbench.sim.mazeio import load_maze
from workbench.sim.record import FORMAT
from workbench.tui.dialogs.path import PathDialog
from workbench.tui.screens.replay import ReplayScreen
from workbench.tui.screens.runs import RunsScreen
from workbench.tui.screens.runs_table import (
    ALL_MAZES,
    THIS_MAZE,
    fit_columns,
    one_profile,
    scope_columns,
)
from workbench.tui.widgets import MazeView

SIZE = (80, 24)
#: the headings of the graded measures, which every view keeps at any width
GRADED = ("Out", "Time s", "Blocks", "Turn deg", "Turns", "Hit/Tch")


def two_runs(tmp_path) -> LabStation:
    station = LabStation.open(BEND, "erobotic", noise="off", record_dir=str(tmp_path / "runs"))
    return run_algorithms(station, "right-wall", "two-distance-local-best")


def text(widget: Static) -> str:
    return str(widget.render())


def table_rows(table: DataTable) -> list[list[str]]:
    return [[str(c) for c in table.get_row_at(i)] for i in range(table.row_count)]


@sync
async def test_the_table_shows_each_run_with_its_measures(tmp_path):
    station = two_runs(tmp_path)
    app = Host(RunsScreen(station, unicode=False), follow_unicode=True)
    async with app.run_test(size=(132, 24)) as pilot:
        await pilot.pause()
        table = app.screen.query_one(DataTable)
        assert [str(c.label) for c in table.columns.values()] == [
            "#",
            "Driver",
            "Out",
            "Time s",
            "Blocks",
            "Turn deg",
            "Turns",
            "Hit/Tch",
            "Eff",
            "Ended",
            "Rec",
        ]
        assert table_rows(table) == [
            ["1", "right-wall", "yes", "11.6", "9.52", "180", "2", "0/0", "1.00", "exit", "yes"],
            [
                "2",
                "two-distance-local-best",
                "yes",
                "19.9",
                "9.67",
                "900",
                "6",
                "0/0",
                "0.98",
                "exit",
                "yes",
            ],
        ]
        assert text(app.screen.query_one("#runs-title")) == "Runs on Bend (erobotic): 2"


def runs_on_two_mazes(tmp_path) -> LabStation:
    """Two runs on Bend, then one on the web maze: the station is left on the web maze."""
    station = two_runs(tmp_path)
    station.load_maze(load_maze("mazes/web.txt"))
    return run_algorithms(station, "two-distance-local-best")


def check_no_column_is_cut(app: Host) -> list[str]:
    """Every heading and cell of the table drawn whole inside the screen; the headings."""
    table = app.screen.query_one(DataTable)
    assert table.virtual_size.width <= table.scrollable_content_region.width
    lines = screen_lines(app)
    headings = [str(c.label) for c in table.columns.values()]
    header = next(line for line in lines if line.lstrip().startswith("#  Driver"))
    assert header.split() == " ".join(headings).split()
    for row in table_rows(table):
        assert any(line.split() == " ".join(row).split() for line in lines), row
    return headings


@pytest.mark.parametrize("width", [80, 100, 132])
@sync
async def test_no_column_is_cut_and_the_rest_is_on_the_detail_line(tmp_path, width):
    station = runs_on_two_mazes(tmp_path)
    screen = RunsScreen(station, unicode=False)
    app = Host(screen, follow_unicode=True)
    async with app.run_test(size=(width, 24)) as pilot:
        await pilot.pause()
        # the station's maze only: the one run on the web maze
        title = text(screen.query_one("#runs-title"))
        assert (
            title == "Runs on Web Simulator lab maze (erobotic): 1, 2 on other mazes (a shows all)"
        )
        headings = check_no_column_is_cut(app)
        assert headings[:3] == ["#", "Driver", "Out"] and "Maze" not in headings
        assert set(GRADED) <= set(headings)
        assert [row[1] for row in table_rows(screen.query_one(DataTable))] == [
            "two-distance-local-best"
        ]
        detail = text(screen.query_one("#runs-detail"))
        eff = f"Eff {station.runs[2].metrics.efficiency:.2f}"
        assert detail.startswith(
            "run 3: algorithm two-distance-local-best on Web Simulator lab maze (erobotic"
        )
        assert (eff in detail) == ("Eff" not in headings)

        await pilot.press("a")
        await pilot.pause()
        # one profile: the title names it, and its column gives the names the room
        title = text(screen.query_one("#runs-title"))
        assert title.startswith("Runs on every maze: 3, all erobotic, by maze")
        headings = check_no_column_is_cut(app)
        assert headings[:4] == ["#", "Driver", "Maze", "Out"] and "Profile" not in headings
        assert set(GRADED) <= set(headings)
        rows = table_rows(screen.query_one(DataTable))
        assert [(row[0], row[2]) for row in rows][:2] == [("1", "Bend"), ("2", "Bend")]
        # where the names do not fit whole they are shortened, marked, and said whole below
        web = rows[2][2]
        assert web == "Web Simulator lab maze" or (
            web.endswith("~") and "Web Simulator lab maze".startswith(web[:-1])
        )
        if width == 132:
            assert "Ended" in headings and "Rec" in headings

        await pilot.press("a")
        await pilot.pause()
        assert screen.query_one(DataTable).row_count == 1


@sync
async def test_touches_show_apart_from_collisions_in_the_table_and_the_replay(tmp_path):
    # the Web wall-following program feels for the wall ahead with its touch sensor
    maze = load_maze("mazes/web.txt")
    station = LabStation.open(maze, "web", noise="off", record_dir=str(tmp_path / "runs"))
    run = run_algorithms(station, "web-wall-following").runs[0]
    m = run.metrics
    assert run.ended == "exit" and m.collisions == 0 and m.touches >= 5
    app = Host(RunsScreen(station, unicode=False), follow_unicode=True)
    async with app.run_test(size=SIZE) as pilot:
        await pilot.pause()
        table = app.screen.query_one(DataTable)
        assert table_rows(table)[0][7] == f"0/{m.touches}"
        assert "Hit/Tch = collisions/touch-sensor bumps" in text(app.screen.query_one("#runs-help"))
        detail = text(app.screen.query_one("#runs-detail"))
        assert f"0 collisions, {m.touches} touches;" in detail
        await pilot.press("enter")
        await pilot.pause()
        replay_screen = app.screen
        assert isinstance(replay_screen, ReplayScreen)
        panel = text(replay_screen.query_one("#replay-tick"))
        assert "touch" not in panel.split("So far")[1]  # no bump yet at the first tick
        await pilot.press("end")
        await pilot.pause()
        panel = text(replay_screen.query_one("#replay-tick"))
        assert f"0 collisions,\n{m.touches} touches (touch sensor)" in panel
        assert panel.endswith("End: out through the exit")


@sync
async def test_new_runs_appear_when_the_screen_comes_back(tmp_path):
    station = two_runs(tmp_path)
    screen = RunsScreen(station)
    app = Host(screen, follow_unicode=True)
    async with app.run_test(size=SIZE) as pilot:
        await pilot.press("enter")
        await pilot.pause()
        assert isinstance(app.screen, ReplayScreen)
        run_algorithms(station, "right-wall")
        await pilot.press("escape")
        await pilot.pause()
        assert app.screen is screen and screen.query_one(DataTable).row_count == 3


@sync
async def test_no_runs_yet_and_a_run_without_a_record(tmp_path):
    station = LabStation.open(BEND, "erobotic", noise="off")
    screen = RunsScreen(station)
    app = Host(screen, follow_unicode=True)
    async with app.run_test(size=SIZE) as pilot:
        await pilot.pause()
        assert text(screen.query_one("#runs-help")).startswith("No runs yet")
        run_algorithms(station, "right-wall")
        screen.refresh_runs()
        await pilot.pause()
        await pilot.press("enter")
        await pilot.pause()
        assert app.screen is screen
        assert screen.status.startswith("run 1 was not recorded")


@sync
async def test_replay_steps_through_the_recorded_run(tmp_path):
    station = two_runs(tmp_path)
    app = Host(RunsScreen(station, unicode=False), follow_unicode=True)
    async with app.run_test(size=SIZE) as pilot:
        await pilot.press("down", "enter")
        await pilot.pause()
        replay_screen = app.screen
        assert isinstance(replay_screen, ReplayScreen)
        replay = replay_screen.replay
        assert replay.title == "two-distance-local-best on Bend"
        assert replay_screen.maze is station.maze and replay_screen.note == ""
        view = replay_screen.query_one(MazeView)
        assert view.robot_cell == BEND.start
        await pilot.press("right", "right", "right")
        assert replay.index == 3
        frame = replay.frame()
        panel = text(replay_screen.query_one("#replay-tick"))
        assert panel.startswith(f"Tick 4/{len(replay)}  t {frame.t:.2f} s")
        assert f"State {frame.state}" in panel
        for port, value in frame.sensors.items():
            assert f"port {port} distance" in panel and f": {value:.1f}" in panel
        await pilot.press("left")
        assert replay.index == 2
        await pilot.press("end")
        await pilot.pause()
        assert replay.at_end and view.robot_cell == BEND.exits[0]
        assert "End: out through the exit" in text(replay_screen.query_one("#replay-tick"))
        assert "exit" in text(replay_screen.query_one("#replay-log"))
        await pilot.press("home")
        assert replay.index == 0 and view.robot_cell == BEND.start
        await pilot.press("pagedown")
        assert replay.index == 10


@sync
async def test_replay_plays_at_a_speed_and_pauses(tmp_path):
    station = two_runs(tmp_path)
    app = Host(RunsScreen(station), follow_unicode=True)
    async with app.run_test(size=SIZE) as pilot:
        await pilot.press("enter")
        await pilot.pause()
        screen = app.screen
        replay = screen.replay
        await pilot.press("plus", "plus", "plus")
        assert replay.speed == 10.0
        await pilot.press("minus")
        assert replay.speed == 4.0
        await pilot.press("space")
        assert replay.playing
        await pilot.pause(0.3)
        await pilot.press("space")
        assert not replay.playing and replay.index > 0
        assert "paused at 4x" in text(screen.query_one("#replay-tick"))
        replay.speed = 50.0
        await pilot.press("space")
        for _ in range(40):
            await pilot.pause(0.05)
            if replay.at_end:
                break
        assert replay.at_end and not replay.playing


@sync
async def test_open_a_record_by_path_and_a_malformed_one(tmp_path):
    station = two_runs(tmp_path)
    screen = RunsScreen(station)
    app = Host(screen, follow_unicode=True)
    bad = tmp_path / "bad.jsonl"
    bad.write_text(
        json.dumps({"type": "header", "format": FORMAT})
        + "\n"
        + json.dumps({"t": 0.0, "pose": [1, 2]})
        + "\n"
    )
    async with app.run_test(size=SIZE) as pilot:
        await pilot.press("o")
        assert isinstance(app.screen, PathDialog)
        app.screen.query_one(Input).value = str(bad)
        await pilot.press("enter")
        await pilot.pause()
        assert isinstance(app.screen, PathDialog)  # asked again with the reason
        assert screen.status == f'{bad}:2: "pose" must be [x, y, heading], three numbers'
        assert screen.status in text(app.screen.query_one("#error"))
        await pilot.press("escape")
        await pilot.pause()
        assert app.screen is screen
        await pilot.press("o")
        app.screen.query_one(Input).value = station.runs[0].record
        await pilot.press("enter")
        await pilot.pause()
        assert isinstance(app.screen, ReplayScreen)
        assert app.screen.replay.title == "right-wall on Bend"


@sync
async def test_replay_of_a_run_whose_maze_cannot_be_found(tmp_path):
    station = two_runs(tmp_path)
    record = station.runs[0].record
    app = Host(ReplayScreen(record), follow_unicode=True)  # no known mazes; bend.txt is nowhere
    async with app.run_test(size=SIZE) as pilot:
        await pilot.pause()
        screen = app.screen
        assert screen.maze is None and "bend.txt is not found" in screen.note
        assert not screen.query(MazeView)
        await pilot.press("right")
        assert screen.replay.index == 1


@sync
async def test_runs_that_end_while_the_screen_is_open_appear(tmp_path):
    station = two_runs(tmp_path)
    screen = RunsScreen(station)
    app = Host(screen, follow_unicode=True)
    async with app.run_test(size=SIZE) as pilot:
        run_algorithms(station, "right-wall")
        screen.show_snapshot(station.snapshot())
        await pilot.pause()
        assert screen.query_one(DataTable).row_count == 3


@pytest.mark.parametrize("unicode", [False, True])
@sync
async def test_both_views_keep_every_graded_measure_at_80x24_with_long_driver_names(
    tmp_path, unicode
):
    station = runs_with_long_driver_names(tmp_path)
    screen = RunsScreen(station, unicode=unicode)
    app = Host(screen, follow_unicode=True)
    turn = "Turn °" if unicode else "Turn deg"
    graded = [turn if g == "Turn deg" else g for g in GRADED]
    cut = "…" if unicode else "~"
    async with app.run_test(size=SIZE) as pilot:
        await pilot.pause()
        for scope in ("this maze", "all mazes"):
            assert screen.scope == scope
            table = screen.query_one(DataTable)
            headings = [str(c.label) for c in table.columns.values()]
            assert set(graded) <= set(headings), (scope, headings)
            assert table.virtual_size.width <= table.scrollable_content_region.width
            rows = {row[0]: row for row in table_rows(table)}
            program = rows["1"][1]
            assert program.endswith(cut)
            assert "my-own-right-wall-follower-for-the-web-maze.viple".startswith(program[:-1])
            m = station.runs[0].metrics
            figures = [f"{m.exit_time:.1f}", f"{m.distance_cells:.2f}", f"{m.turn_degrees:.0f}",
                       str(m.turns), f"{m.collisions}/{m.touches}"]  # fmt: skip
            assert rows["1"][-len(figures) :] == figures
            screen_text = "\n".join(screen_lines(app))
            assert all(f in screen_text for f in figures)
            detail = " ".join(text(screen.query_one("#runs-detail")).split())
            chosen = table.get_row_at(table.cursor_row)[0]
            run = station.runs[int(str(chosen)) - 1]
            assert detail.startswith(f"run {run.number}: {run.driver} on ")
            await pilot.press("a")
            await pilot.pause()


def test_the_profile_column_stands_where_the_runs_were_made_with_several(tmp_path):
    erobotic = two_runs(tmp_path)
    web = run_algorithms(LabStation.open(BEND, "web", noise="off"), "right-wall")
    runs = [*erobotic.runs, replace(web.runs[0], number=3)]
    assert one_profile(runs) == "" and one_profile(erobotic.runs) == "erobotic"
    assert "profile" in scope_columns(runs, ALL_MAZES)
    assert "profile" not in scope_columns(erobotic.runs, ALL_MAZES)
    assert not {"maze", "profile"} & scope_columns(runs, THIS_MAZE)
    fitted = fit_columns(runs, False, 78, ALL_MAZES)
    assert fitted.keys[:4] == ("number", "driver", "maze", "profile")
    assert {"reached", "time", "distance", "turning", "turns", "contacts"} <= set(fitted.keys)
    assert [fitted.cells(r, False)[3] for r in runs] == ["erobotic", "erobotic", "web"]
