"""The workbench app driven like a student drives it: keys, pause, step, speed, reset, help,
the command palette, a terminal that is too small, quitting, and the command line."""

from __future__ import annotations

import io
from time import perf_counter

import pytest
from rich.console import Console
from textual.binding import Binding
from textual.command import CommandList
from textual.pilot import Pilot
from textual.widgets import Static

from tests.app.support import maze_file, run, run_panel
from workbench.cli import main
from workbench.control.manual import key_legend
from workbench.tui.app import FOCUS_BINDINGS, AppSetupError, WorkbenchApp, make_app
from workbench.tui.commands import WorkbenchCommands
from workbench.tui.dialogs.help import HelpScreen
from workbench.tui.dialogs.too_small import TooSmallScreen
from workbench.tui.dialogs.unsaved import UnsavedDialog
from workbench.tui.keys import KEY_TABLE
from workbench.tui.screens.editor import EditorScreen
from workbench.tui.screens.main import MainScreen
from workbench.tui.screens.runs import RunsScreen
from workbench.tui.widgets.key_legend import KeyLegend
from workbench.tui.widgets.maze_view import MazeView
from workbench.tui.widgets.run_status import RunStatus
from workbench.wire.settings import AppSettings

ROOM = "#######\n#.....#\n#..S..#\n#.....#\n#######\n"
CORRIDOR = "##########\n#S......E#\n##########\n"


# -- drive-by-wire ------------------------------------------------------------------------------


def test_unity_keys_turn_by_degree_and_move_at_power(tmp_path):
    app = make_app(AppSettings(maze_file(tmp_path, ROOM, "unity"), paused=True, noise="off"))
    start = app.station.snapshot().pose

    async def body(pilot: Pilot) -> None:
        await pilot.press("d")
        app.station.step(60 * 4)
        assert app.station.snapshot().pose.heading == pytest.approx(90, abs=0.5)
        await pilot.press("w")
        app.station.step(60)
        await pilot.press("space")
        app.station.step(30)
        app.refresh_views()
        await pilot.pause()
        pose = app.station.snapshot().pose
        assert pose.y > start.y + 0.5 and pose.x == pytest.approx(start.x, abs=0.05)
        assert app.screen.query_one(MazeView).robot_cell == app.station.snapshot().block
        assert "driver: keys" in run_panel(app)
        assert app.station.keys_used == {"d", "w", "space"}

    run(app, body)


def test_web_keys_spin_until_the_next_key(tmp_path):
    app = make_app(AppSettings(maze_file(tmp_path, ROOM, "web"), paused=True, noise="off"))

    async def body(pilot: Pilot) -> None:
        await pilot.press("a")
        app.station.step(90)  # (-0.2, 0.2) for 1.5 s: a quarter turn left
        assert app.station.snapshot().pose.heading == pytest.approx(270, abs=10)
        await pilot.press("space")
        heading = app.station.snapshot().pose.heading
        app.station.step(60)
        assert app.station.snapshot().pose.heading == pytest.approx(heading, abs=0.01)

    run(app, body)


def test_erobotic_w_drives_exactly_one_block(tmp_path):
    app = make_app(AppSettings(maze_file(tmp_path, CORRIDOR, "erobotic"), paused=True))
    start = app.station.maze.start

    async def body(pilot: Pilot) -> None:
        await pilot.press("w")
        app.station.step(120)
        app.refresh_views()
        await pilot.pause()
        snap = app.station.snapshot()
        assert snap.block == (start[0] + 1, start[1])
        assert snap.metrics.distance_cells == pytest.approx(1.0, abs=1e-6)
        assert app.screen.query_one(MazeView).robot_cell == snap.block

    run(app, body)


@pytest.mark.parametrize("profile", ["unity", "web", "erobotic"])
def test_the_key_legend_follows_the_profile(tmp_path, profile):
    app = make_app(AppSettings(maze_file(tmp_path, ROOM, profile), paused=True))

    async def body(pilot: Pilot) -> None:
        legend = app.screen.query_one(KeyLegend)
        text = str(legend.content)
        assert legend.border_title == f"Keys ({profile})"
        for _key, what in key_legend(profile):
            assert what in text

    run(app, body)


# -- time ----------------------------------------------------------------------------------------


def test_pause_step_speed_and_reset(tmp_path):
    app = make_app(AppSettings(maze_file(tmp_path, ROOM, "unity"), noise="off"))
    station = app.station

    async def body(pilot: Pilot) -> None:
        await pilot.press("w")
        await pilot.pause(0.3)
        assert station.snapshot().time > 0  # the interval runs the simulation in real time
        await pilot.press("p")
        assert station.pacer.paused and "PAUSED" in run_panel(app)
        t = station.snapshot().time
        await pilot.pause(0.2)
        assert station.snapshot().time == t
        await pilot.press("n")
        assert station.snapshot().time == pytest.approx(t + station.session.every / 60)
        assert station.pacer.paused
        seen = []
        for _ in range(5):
            await pilot.press("plus")
            seen.append(run_panel(app).splitlines()[1].split(" at ")[1].split()[0])
        assert seen == ["2x", "4x", "10x", "max", "1x"]
        await pilot.press("r")
        snap = station.snapshot()
        assert snap.time == 0 and snap.block == station.maze.start
        assert station.runs[-1].ended == "reset"
        await pilot.press("p")
        assert not station.pacer.paused and "running" in run_panel(app)

    run(app, body)


def test_a_slow_frame_loses_no_simulated_time(tmp_path):
    app = make_app(AppSettings(maze_file(tmp_path, ROOM, "unity"), paused=True, tick_hz=20))

    async def body(pilot: Pilot) -> None:
        app.station.pacer.paused = False
        app._last_tick = perf_counter() - 0.2  # the next tick comes 200 ms late
        app._tick()
        assert app.station.snapshot().time == pytest.approx(0.2, abs=2 / 60)

    run(app, body)


# -- screens and keys --------------------------------------------------------------------------


KEYED_APP_BINDINGS = [b for b in WorkbenchApp.BINDINGS if b not in FOCUS_BINDINGS]


def test_help_explains_every_key(tmp_path):
    app = make_app(AppSettings(maze_file(tmp_path, ROOM, "web"), paused=True))

    async def body(pilot: Pilot) -> None:
        await pilot.press("question_mark")
        assert isinstance(app.screen, HelpScreen)
        console = Console(width=100, record=True, file=io.StringIO())
        console.print(app.screen.query_one("#help-text", Static).content)
        text = " ".join(console.export_text().split())
        for binding in [*MainScreen.BINDINGS, *KEYED_APP_BINDINGS]:
            info = KEY_TABLE[binding.id]
            if info.group != "Drive":
                assert " ".join(info.explanation.split()) in text
        for _key, what in key_legend("web"):
            assert what in text
        await pilot.press("escape")
        assert isinstance(app.screen, MainScreen)

    run(app, body, size=(120, 40))


def test_help_has_a_labs_section_with_the_labs_screens_keys(tmp_path):
    from workbench.tui.screens.labs import LabsScreen

    app = make_app(AppSettings(paused=True, data_dir=tmp_path / "data"))

    async def body(pilot: Pilot) -> None:
        await pilot.press("l", "question_mark")  # asked on the labs screen
        await pilot.pause()
        assert isinstance(app.screen, HelpScreen)
        console = Console(width=76, record=True, file=io.StringIO())
        console.print(app.screen.query_one("#help-text", Static).content)
        lines = console.export_text().splitlines()
        at = lines.index("Labs")
        section = " ".join(" ".join(lines[at : at + 16]).split())
        for binding in LabsScreen.BINDINGS:
            assert isinstance(binding, Binding)
            info = KEY_TABLE[binding.id]
            shown = binding.key_display or app.get_key_display(binding)
            assert f"{shown} {info.title}: {' '.join(info.explanation.split())[:30]}" in section

    run(app, body)


def test_every_binding_has_an_id_and_a_help_entry():
    for binding in [*MainScreen.BINDINGS, *KEYED_APP_BINDINGS]:
        assert binding.id in KEY_TABLE, binding


def test_the_command_palette_offers_the_bindings_and_runs_them(tmp_path):
    app = make_app(AppSettings(maze_file(tmp_path, ROOM, "unity"), paused=True))

    async def body(pilot: Pilot) -> None:
        provider = WorkbenchCommands(app.screen)
        titles = [title for title, _help, _run in provider._commands()]
        assert "Simulation: pause / resume" in titles and "App: quit" in titles
        assert len(titles) == len(titles) and len(set(titles)) == len(titles)
        await pilot.press("ctrl+p")
        await pilot.pause()
        await pilot.press(*"speed")
        for _ in range(50):  # the palette searches in the background
            await pilot.pause(0.05)
            if app.screen.query_one(CommandList).option_count:
                break
        await pilot.press("enter")
        for _ in range(20):
            await pilot.pause(0.05)
            if app.station.pacer.speed == 2.0:
                break
        assert app.station.pacer.speed == 2.0

    run(app, body)


def test_unicode_and_trail_toggles(tmp_path):
    app = make_app(AppSettings(maze_file(tmp_path, ROOM, "unity"), paused=True))

    async def body(pilot: Pilot) -> None:
        view = app.screen.query_one(MazeView)
        assert not view.unicode and view.trail and app.has_class("-ascii")
        await pilot.press("u", "t")
        assert view.unicode and not view.trail
        assert app.unicode and not app.has_class("-ascii")  # panel rules in Unicode too
        await pilot.press("u", "t")
        assert not view.unicode and view.trail

    run(app, body)


def test_a_terminal_below_80x24_gets_a_message_instead_of_the_layout(tmp_path):
    app = make_app(AppSettings(maze_file(tmp_path, ROOM, "unity"), paused=True))

    async def body(pilot: Pilot) -> None:
        assert isinstance(app.screen, TooSmallScreen)
        text = str(app.screen.query_one("#too-small-text").render())
        assert "70x20" in text and "80x24" in text
        await pilot.press("w", "question_mark")
        assert isinstance(app.screen, TooSmallScreen)
        assert app.station.keys_used == set()
        await pilot.resize_terminal(80, 24)
        await pilot.pause(0.1)
        assert isinstance(app.screen, MainScreen)
        await pilot.resize_terminal(79, 24)
        await pilot.pause(0.1)
        assert isinstance(app.screen, TooSmallScreen)

    run(app, body, size=(70, 20))


def test_a_small_terminal_at_the_names_dialog_then_enlarged_reaches_the_main_screen(tmp_path):
    # the size message covers the names dialog; once the terminal is big enough the dialog
    # is back, and after it the main screen (not the size message again)
    app = make_app(AppSettings(maze_file(tmp_path, ROOM, "unity"), paused=True, student="ann",
                   ask_names=True, data_dir=tmp_path / "data"))  # fmt: skip

    async def body(pilot: Pilot) -> None:
        await pilot.pause()
        assert isinstance(app.screen, TooSmallScreen)
        await pilot.resize_terminal(80, 24)
        await pilot.pause(0.1)
        assert not isinstance(app.screen, TooSmallScreen)
        assert "Who is at this robot?" in str(app.screen.query_one("#dialog").border_title)
        await pilot.press("enter")
        await pilot.pause(0.2)
        assert isinstance(app.screen, MainScreen)
        assert not any(isinstance(s, TooSmallScreen) for s in app.screen_stack)

    run(app, body, size=(70, 20))


def test_ctrl_q_in_the_editor_with_unsaved_changes_asks_first(tmp_path):
    app = make_app(AppSettings(maze_file(tmp_path, ROOM, "unity"), paused=True))

    async def body(pilot: Pilot) -> None:
        await pilot.press("e")
        await pilot.press("right", "space")  # an unsaved wall
        await pilot.press("ctrl+q")
        await pilot.pause()
        assert isinstance(app.screen, UnsavedDialog) and app.is_running
        await pilot.press("escape")  # cancel: back in the editor, nothing lost
        await pilot.pause()
        assert isinstance(app.screen, EditorScreen) and app.screen.dirty
        await pilot.press("ctrl+q")
        await pilot.pause()
        await pilot.press("d")  # discard, then quit
        await pilot.pause()

    run(app, body)
    assert app.return_code == 0


def test_ctrl_q_quits_and_keeps_the_open_run(tmp_path):
    app = make_app(AppSettings(maze_file(tmp_path, ROOM, "unity"), paused=True))

    async def body(pilot: Pilot) -> None:
        await pilot.press("w")
        await pilot.press("ctrl+c")  # does not quit
        assert app.is_running
        await pilot.press("ctrl+q")

    run(app, body)
    assert app.return_code == 0
    assert [r.ended for r in app.station.runs] == ["stopped"]


def test_e_opens_the_maze_editor_and_capital_r_the_runs(tmp_path):
    app = make_app(AppSettings(maze_file(tmp_path, ROOM, "unity"), paused=True))

    async def body(pilot: Pilot) -> None:
        await pilot.press("w", "r")  # one run, ended by the reset
        await pilot.press("e")
        assert isinstance(app.screen, EditorScreen)
        titles = [t for t, _h, _r in WorkbenchCommands(app.screen)._commands()]
        assert "App: quit" in titles and any(t.startswith("Maze editor: ") for t in titles)
        edited = app.station.maze.with_block(5, 2, True)
        app.station.load_maze(edited)  # what the editor does with a valid edit on leaving
        app.screen.dismiss(edited)
        await pilot.pause()
        assert isinstance(app.screen, MainScreen)
        view = app.screen.query_one(MazeView)
        assert view.maze is edited and view.robot_cell == edited.start
        assert app.sub_title == "room (unity)"
        await pilot.press("R")
        assert isinstance(app.screen, RunsScreen)
        await pilot.press("escape")
        await pilot.pause()
        assert isinstance(app.screen, MainScreen)

    run(app, body)


# -- setting up ----------------------------------------------------------------------------------


def test_make_app_reports_bad_arguments_in_words(tmp_path):
    with pytest.raises(AppSetupError, match="unknown profile 'lego'"):
        make_app(AppSettings(profile="lego"))
    with pytest.raises(AppSetupError, match="unknown noise level"):
        make_app(AppSettings(noise="loud"))
    with pytest.raises(AppSetupError, match="cannot open the maze"):
        make_app(AppSettings(tmp_path / "missing.txt"))
    bad = tmp_path / "bad.txt"
    bad.write_text("#####\n#.X.#\n#####\n")
    with pytest.raises(AppSetupError, match="unknown character"):
        make_app(AppSettings(bad))


def test_make_app_defaults_to_the_bundled_maze():
    app = make_app(AppSettings(paused=True))
    assert app.station.maze.name == "Unity default" and app.station.profile == "unity"
    assert app.station.pacer.paused


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["--profile", "lego"], "unknown profile 'lego'"),
        (["--maze", "no/such/maze.txt"], "cannot read"),
        (["--noise", "loud"], "unknown noise level"),
    ],
)
def test_workbench_with_bad_arguments_exits_2_before_the_app(capsys, args, message):
    assert main(args) == 2
    err = capsys.readouterr().err
    assert err.startswith("workbench: ") and message in err and "Traceback" not in err


def test_the_run_panel_counts_a_bumper_touch_apart_from_collisions(tmp_path):
    # web: a touch sensor at the front; w drives at the course's Forward speed
    app = make_app(AppSettings(maze_file(tmp_path, ROOM, "web"), paused=True, noise="off"))

    async def body(pilot: Pilot) -> None:
        await pilot.press("w")
        app.station.step(60 * 3)  # drives up to the wall above and presses the bumper
        app.refresh_views()
        await pilot.pause()
        lines = app.screen.query_one(RunStatus).lines
        assert lines[-1] == "collisions 0 | touches 1"
        assert lines[-2].startswith("turned ") and "collisions" not in lines[-2]
        metrics = app.station.snapshot().metrics
        assert (metrics.collisions, metrics.touches) == (0, 1)

    run(app, body)


def test_drive_keys_follow_the_focus_and_a_new_keymap_though_bindings_are_looked_up_once(
    tmp_path,
):
    """The main screen builds its key bindings once and keeps them while nothing they depend on
    changes; moving the focus or changing the keymap builds them again, so keys keep working."""
    app = make_app(AppSettings(maze_file(tmp_path, ROOM, "unity"), paused=True, noise="off"))

    def heading() -> float:
        app.station.step(60 * 4)
        return app.station.snapshot().pose.heading

    async def body(pilot: Pilot) -> None:
        screen = app.screen
        assert isinstance(screen, MainScreen)
        chain = screen._binding_chain
        assert screen._binding_chain is chain  # looked up once, not for every key
        await pilot.press("d")
        assert heading() == pytest.approx(90, abs=0.5)
        assert app.focused is not None
        screen.set_focus(None)
        await pilot.pause()
        assert screen._binding_chain is not chain  # the focus moved: built again
        await pilot.press("d")
        assert heading() == pytest.approx(180, abs=0.5)
        app.set_keymap({"drive.right": "l"})
        await pilot.press("l")
        assert heading() == pytest.approx(270, abs=0.5)
        await pilot.press("d")  # no longer a drive key
        assert heading() == pytest.approx(270, abs=0.5)

    run(app, body)
