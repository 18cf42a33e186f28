"""The maze editor screen, driven through a tiny host app with App.run_test()."""

from __future__ import annotations

from textual.widgets import Input, OptionList, Select

from tests.app.support import Host, sync
from workbench.control.station import LabStation
from workbench.sim.mazefile import write_maze
from workbench.sim.mazeio import load_maze
from workbench.tui.dialogs.generate import GenerateDialog
from workbench.tui.dialogs.path import PathDialog
from workbench.tui.dialogs.size import SizeDialog
from workbench.tui.dialogs.unsaved import UnsavedDialog
from workbench.tui.screens.editor import EditorScreen
from workbench.tui.widgets import MazeView

ROOM_TEXT = "#######\n#S....#\n#.....#\n#....E#\n#######\n"
SIZE = (80, 24)


def room(tmp_path, name="room.txt"):
    path = tmp_path / name
    path.write_text(ROOM_TEXT)
    maze = load_maze(path)
    return path, LabStation.open(maze, "erobotic", noise="off")


def editor_app(tmp_path, with_path=True):
    path, station = room(tmp_path)
    screen = EditorScreen(station, str(path) if with_path else None, unicode=False)
    return Host(screen), screen, station, path


@sync
async def test_space_toggles_the_wall_under_the_cursor_and_undo_redo(tmp_path):
    app, screen, _, _ = editor_app(tmp_path)
    async with app.run_test(size=SIZE) as pilot:
        assert screen.editor.cursor == (1, 1)
        await pilot.press("right", "right", "down", "space")
        assert screen.editor.cursor == (3, 2)
        assert screen.editor.maze.is_wall(3, 2) and screen.dirty
        view = screen.query_one(MazeView)
        assert view.maze is screen.editor.maze and view.cursor == (3, 2)
        await pilot.press("ctrl+z")
        assert not screen.editor.maze.is_wall(3, 2) and not screen.dirty
        assert view.maze is screen.editor.maze
        await pilot.press("ctrl+y")
        assert screen.editor.maze.is_wall(3, 2)
        assert "(3, 2) is wall now" not in screen.status  # redo says so instead
        assert screen.status == "redone"


@sync
async def test_a_click_on_a_block_toggles_it(tmp_path):
    app, screen, _, _ = editor_app(tmp_path)
    async with app.run_test(size=SIZE) as pilot:
        await pilot.click("#editor-maze", offset=(2 * 4 + 1, 2))
        assert screen.editor.maze.is_wall(4, 2) and screen.editor.cursor == (4, 2)
        assert screen.status == "(4, 2) is wall now"
        await pilot.click("#editor-maze", offset=(2 * 4, 2))
        assert not screen.editor.maze.is_wall(4, 2)


@sync
async def test_walling_the_start_is_refused_with_a_reason(tmp_path):
    app, screen, _, _ = editor_app(tmp_path)
    async with app.run_test(size=SIZE) as pilot:
        await pilot.press("space")
        assert not screen.editor.maze.is_wall(1, 1) and not screen.dirty
        assert screen.status.startswith("the start is on this block")


@sync
async def test_start_cycles_its_heading_and_x_toggles_an_exit(tmp_path):
    app, screen, _, _ = editor_app(tmp_path)
    async with app.run_test(size=SIZE) as pilot:
        await pilot.press("s")
        assert screen.editor.maze.heading == "down"
        await pilot.press("right", "s")
        assert screen.editor.maze.start == (2, 1)
        await pilot.press("x")
        assert screen.editor.maze.is_exit(2, 1)
        assert "start is on an exit" in [p.message for p in screen.editor.problems]
        await pilot.press("x")
        assert not screen.editor.maze.is_exit(2, 1) and screen.editor.valid


@sync
async def test_the_problem_list_follows_edits_and_moves_the_cursor(tmp_path):
    app, screen, _, _ = editor_app(tmp_path)
    async with app.run_test(size=SIZE) as pilot:
        problems = screen.query_one("#editor-problems", OptionList)
        assert problems.option_count == 0
        await pilot.press(*["right"] * 5, "space")  # open the right-hand boundary at (6, 1)
        await pilot.pause()
        assert problems.option_count == 1
        assert str(problems.get_option_at_index(0).prompt) == (
            "(6, 1) open floor on the outer boundary: the robot could leave the maze"
        )
        await pilot.press("left", "left", "left", "p")
        assert screen.editor.cursor == (6, 1)
        assert screen.status == "(6, 1): make it a # wall or an E exit"
        await pilot.press("left", "left", "tab", "down", "enter")
        assert screen.editor.cursor == (6, 1) and app.focused is None
        await pilot.press("space")
        await pilot.pause()
        assert problems.option_count == 0


@sync
async def test_ctrl_s_saves_atomically_and_clears_dirty(tmp_path):
    app, screen, _, path = editor_app(tmp_path)
    async with app.run_test(size=SIZE) as pilot:
        await pilot.press("right", "space", "ctrl+s")
        assert not screen.dirty and screen.status == f"saved to {path}"
        assert load_maze(path).is_wall(2, 1)
        assert sorted(p.name for p in tmp_path.iterdir()) == ["room.txt"]


@sync
async def test_save_as_asks_for_a_path_and_reports_failures(tmp_path):
    app, screen, _, path = editor_app(tmp_path, with_path=False)
    async with app.run_test(size=SIZE) as pilot:
        await pilot.press("down", "space", "ctrl+s")
        assert isinstance(app.screen, PathDialog)
        field = app.screen.query_one(Input)
        field.value = str(tmp_path / "missing" / "m.txt")
        await pilot.press("enter")
        await pilot.pause()
        assert isinstance(app.screen, PathDialog)  # asked again, with the reason
        assert "the folder" in screen.status and "does not exist" in screen.status
        assert screen.dirty and screen.editor.maze.is_wall(1, 2)
        app.screen.query_one(Input).value = str(tmp_path / "new.txt")
        await pilot.press("enter")
        await pilot.pause()
        assert app.screen is screen and not screen.dirty
        assert load_maze(tmp_path / "new.txt").is_wall(1, 2)
        assert path.read_text() == ROOM_TEXT


@sync
async def test_escape_without_changes_leaves_and_keeps_the_run(tmp_path):
    app, _screen, station, _ = editor_app(tmp_path)
    maze = station.maze
    async with app.run_test(size=SIZE) as pilot:
        await pilot.press("escape")
        await pilot.pause()
        assert app.results == [None] and station.maze is maze


@sync
async def test_unsaved_prompt_cancel_stays_in_the_editor(tmp_path):
    app, screen, _station, _ = editor_app(tmp_path)
    async with app.run_test(size=SIZE) as pilot:
        await pilot.press("right", "space", "escape")
        assert isinstance(app.screen, UnsavedDialog)
        await pilot.press("c")
        await pilot.pause()
        assert app.screen is screen and screen.dirty and app.results == []
        await pilot.press("escape", "escape")  # escape in the prompt cancels too
        await pilot.pause()
        assert app.screen is screen


@sync
async def test_unsaved_prompt_discard_leaves_the_station_and_file_alone(tmp_path):
    app, _screen, station, path = editor_app(tmp_path)
    maze = station.maze
    async with app.run_test(size=SIZE) as pilot:
        await pilot.press("right", "space", "escape", "d")
        await pilot.pause()
        assert app.results == [None] and station.maze is maze
        assert path.read_text() == ROOM_TEXT


@sync
async def test_unsaved_prompt_save_writes_and_gives_the_station_the_maze(tmp_path):
    app, _screen, station, path = editor_app(tmp_path)
    async with app.run_test(size=SIZE) as pilot:
        await pilot.press("right", "space", "escape", "s")
        await pilot.pause()
        (given,) = app.results
        assert given is station.maze and station.maze.is_wall(2, 1)
        assert load_maze(path).is_wall(2, 1)
        assert "edited maze" in app.said[-1]


@sync
async def test_unsaved_prompt_save_without_a_path_asks_for_one_then_leaves(tmp_path):
    app, _screen, station, _ = editor_app(tmp_path, with_path=False)
    async with app.run_test(size=SIZE) as pilot:
        await pilot.press("right", "space", "escape", "s")
        await pilot.pause()
        assert isinstance(app.screen, PathDialog)
        app.screen.query_one(Input).value = str(tmp_path / "saved.txt")
        await pilot.press("enter")
        await pilot.pause()
        assert len(app.results) == 1 and station.maze.is_wall(2, 1)
        assert load_maze(tmp_path / "saved.txt").is_wall(2, 1)


@sync
async def test_leaving_with_an_invalid_maze_keeps_the_old_one_on_the_station(tmp_path):
    app, screen, station, _ = editor_app(tmp_path)
    maze = station.maze
    async with app.run_test(size=SIZE) as pilot:
        await pilot.press(*["right"] * 5, "space", "escape", "d")  # discard: nothing saved
        await pilot.pause()
        assert station.maze is maze
    app, screen, station, _path = editor_app(tmp_path)
    async with app.run_test(size=SIZE) as pilot:
        await pilot.press(*["right"] * 5, "space", "ctrl+s", "escape")
        await pilot.pause()
        assert app.results == [None] and station.maze is not screen.editor.maze
        assert app.said[-1] == "the maze has 1 problem, so the robot stays on the previous maze"


@sync
async def test_new_maze_dialog_checks_the_size(tmp_path):
    app, screen, _, _ = editor_app(tmp_path)
    async with app.run_test(size=SIZE) as pilot:
        await pilot.press("n")
        dialog = app.screen
        assert isinstance(dialog, SizeDialog)
        dialog.query_one("#width", Input).value = "2"
        await pilot.press("enter")
        await pilot.pause()
        assert app.screen is dialog
        assert str(dialog.query_one("#error").render()) == "width must be 3 to 200 blocks, not 2"
        dialog.query_one("#width", Input).value = ""
        await pilot.press("enter")
        assert "width is empty" in str(dialog.query_one("#error").render())
        dialog.query_one("#width", Input).value = "9"
        dialog.query_one("#height", Input).value = "6"
        await pilot.press("enter")
        await pilot.pause()
        assert app.screen is screen
        maze = screen.editor.maze
        assert (maze.width, maze.height, maze.start) == (9, 6, (1, 1))
        assert screen.editor.path is None and screen.dirty
        await pilot.press("n", "escape")
        await pilot.pause()
        assert app.screen is screen and screen.editor.maze is maze


@sync
async def test_generate_dialog_checks_and_generates(tmp_path):
    app, screen, _, _ = editor_app(tmp_path)
    async with app.run_test(size=SIZE) as pilot:
        await pilot.press("g")
        dialog = app.screen
        assert isinstance(dialog, GenerateDialog)
        dialog.query_one("#seed", Input).value = ""
        await pilot.press("enter")
        await pilot.pause()
        assert app.screen is dialog
        assert "seed '' is not a whole number" in str(dialog.query_one("#error").render())
        dialog.query_one("#width", Input).value = "5"
        dialog.query_one("#height", Input).value = "4"
        dialog.query_one("#seed", Input).value = "3"
        dialog.query_one("#style", Select).value = "braid"
        dialog.query_one("#exit", Select).value = "center"
        await pilot.click("#ok")
        await pilot.pause()
        assert app.screen is screen
        maze = screen.editor.maze
        assert (maze.width, maze.height) == (11, 9) and maze.name == "braid 5x4 seed 3"
        assert screen.editor.valid and screen.editor.cursor == maze.start
        await pilot.press("g")  # the dialog remembers the last options
        assert app.screen.query_one("#seed", Input).value == "3"
        assert app.screen.query_one("#style", Select).value == "braid"
        await pilot.press("escape", "ctrl+z")
        await pilot.pause()
        assert screen.editor.maze == load_maze(tmp_path / "room.txt")


@sync
async def test_unicode_follows_the_screen_setting(tmp_path):
    app, screen, _, _ = editor_app(tmp_path)
    async with app.run_test(size=SIZE) as pilot:
        await pilot.press("u")
        assert screen.unicode and screen.query_one(MazeView).unicode
        screen.set_unicode(False)
        assert not screen.query_one(MazeView).unicode


def test_the_editor_saves_into_the_station_maze_file_it_was_given(tmp_path):
    maze_path, station = room(tmp_path)
    write_maze(maze_path, station.maze.with_block(3, 2, True))
    screen = EditorScreen(station, str(maze_path))
    assert screen.editor.path == str(maze_path) and screen.editor.maze is station.maze


@sync
async def test_ask_before_quitting_runs_the_action_after_save_or_discard_only(tmp_path):
    app, screen, _, path = editor_app(tmp_path)
    done: list[str] = []
    async with app.run_test(size=SIZE) as pilot:
        screen.ask_before(lambda: done.append("clean"))
        assert done == ["clean"]  # nothing to save: at once
        await pilot.press("right", "space")
        screen.ask_before(lambda: done.append("cancelled"))
        await pilot.pause()
        await pilot.press("c")
        await pilot.pause()
        screen.ask_before(lambda: done.append("discarded"))
        await pilot.pause()
        await pilot.press("d")
        await pilot.pause()
        assert done == ["clean", "discarded"] and path.read_text() == ROOM_TEXT
        screen.ask_before(lambda: done.append("saved"))
        await pilot.pause()
        await pilot.press("s")
        await pilot.pause()
        assert done[-1] == "saved" and load_maze(path).is_wall(2, 1)


@sync
async def test_a_failed_save_as_keeps_the_typed_path(tmp_path):
    app, _screen, _, _ = editor_app(tmp_path, with_path=False)
    async with app.run_test(size=SIZE) as pilot:
        await pilot.press("a")
        typed = str(tmp_path / "no" / "such" / "dir.txt")
        app.screen.query_one(Input).value = typed
        await pilot.press("enter")
        await pilot.pause()
        assert isinstance(app.screen, PathDialog)
        assert app.screen.query_one(Input).value == typed
