"""A VIPLE program loaded in the app: chosen in the algorithm dialog, driving the robot through
the station, answering keys typed on the terminal, printing to the program panel's console."""

from __future__ import annotations

from textual.pilot import Pilot
from textual.widgets import Input, Static

from tests.app.support import maze_file, run
from tests.program.builder import ProgramBuilder
from workbench.program.keys import RELEASE_GAP
from workbench.tui.app import make_app
from workbench.tui.dialogs.algorithm import AlgorithmModal
from workbench.tui.widgets.algorithm_state import AlgorithmState
from workbench.tui.widgets.program_state import ProgramState
from workbench.wire.settings import AppSettings

ROOM = "#########\n#.......#\n#...S...#\n#.......#\n#########\n"


def drive_by_wire(tmp_path, name: str = "wire.viple") -> str:
    """w drives at half power and prints; d spins; the release stops; the right distance
    sensor (port 1) is kept in a global; a greeting at the start."""
    b = ProgramBuilder()
    main = b.panel("Main")
    b.robot(main)
    b.var("side", "System.Double")
    hello = main.add(3, '"hello"')
    main.chain(hello, main.add(28, ""))
    w = main.add(13, "22")
    go = main.add(20, "0.5", "0.5", "Robot/IoT Controller 0", "3", "5")
    said = main.add(2, '"going " + value')
    main.chain(w, go, said, main.add(28, ""))
    d = main.add(13, "3")
    main.chain(d, main.add(20, "0.4", "-0.4", "Robot/IoT Controller 0", "3", "5"))
    release = main.add(29, "")
    main.chain(release, main.add(20, "0", "0", "Robot/IoT Controller 0", "3", "5"))
    side = main.add(23, "Robot/IoT Controller 0", "1")
    main.chain(side, main.add(1, "side"))
    return b.write(tmp_path / name)


def bad_program(tmp_path) -> str:
    b = ProgramBuilder()
    main = b.panel("Main")
    for i in range(12):  # twelve problems: more than the dialog shows at once at 80x24
        main.chain(main.add(3, "1"), main.add(2, f"value + state.missing{i}"))
    return b.write(tmp_path / "bad.viple")


async def load(pilot: Pilot, path: str) -> AlgorithmModal:
    await pilot.press("g")
    await pilot.pause()
    dialog = pilot.app.screen
    assert isinstance(dialog, AlgorithmModal)
    dialog.query_one("#alg-path", Input).value = path
    await dialog.choose(path)
    await pilot.pause()
    return dialog


def test_a_program_loads_drives_answers_keys_and_prints(tmp_path):
    app = make_app(AppSettings(maze_file(tmp_path, ROOM), paused=True, noise="off"))
    path = drive_by_wire(tmp_path)

    async def body(pilot: Pilot) -> None:
        station = app.station
        dialog = await load(pilot, path)
        shown = str(dialog.query_one("#alg-sensors", Static).render())
        assert "keys it answers: d, w, release" in shown
        assert "distance on port 1" in shown
        await pilot.click("#alg-start")
        await pilot.pause()
        assert not isinstance(app.screen, AlgorithmModal)
        assert str(station.session.driver) == "VIPLE program wire.viple"
        station.pause()
        start = station.snapshot().pose
        station.step(6)  # the start message reaches Print Line
        await pilot.press("w")
        station.step(60)  # one second: w is released after the quiet gap
        moved = station.snapshot().pose
        assert moved.x != start.x or moved.y != start.y
        run_ = station.driving.controller
        assert [f.what for f in run_.fired] == ["key w", "key release"]
        assert run_.fired[1].time - run_.fired[0].time >= RELEASE_GAP - 0.05
        station.step(30)
        still = station.snapshot().pose
        station.step(30)
        assert station.snapshot().pose == still  # the release stopped the wheels
        app.refresh_views()
        await pilot.pause()
        panel = app.screen.query_one(ProgramState)
        assert panel.display and not app.screen.query_one(AlgorithmState).display
        assert [line.split(None, 1)[1] for line in panel.console_lines] == ["hello", "going w"]
        assert "side=" in str(panel.query_one("#program-vars", Static).render())
        assert "key release" in str(panel.query_one("#program-events", Static).render())
        # an arrow key goes to the program too (it answers none: nothing fires, nothing breaks)
        await pilot.press("up")
        station.step(3)
        assert run_.held == frozenset({"up"})
        # space stops the program; the keys drive again
        await pilot.press("space")
        assert station.driving is None
        assert station.runs[-1].driver.digest == station.program.digest
        await pilot.press("w")
        assert station.keys_used == {"w"}

    run(app, body)


def test_a_held_key_repeating_stays_held(tmp_path):
    app = make_app(AppSettings(maze_file(tmp_path, ROOM), paused=True, noise="off"))
    path = drive_by_wire(tmp_path)

    async def body(pilot: Pilot) -> None:
        station = app.station
        await load(pilot, path)
        await pilot.press("escape")
        await pilot.press("x")  # x starts the chosen program
        station.pause()
        for _ in range(10):  # auto-repeat: a w every 0.2 s for 2 s
            await pilot.press("w")
            station.step(12)
        run_ = station.driving.controller
        assert [f.what for f in run_.fired] == ["key w"]
        await pilot.press("d")  # another key: w is released, then d pressed
        station.step(3)
        assert [f.what for f in run_.fired] == ["key w", "key release", "key d"]

    run(app, body)


def test_a_bad_program_lists_every_problem_and_the_app_goes_on(tmp_path):
    app = make_app(AppSettings(maze_file(tmp_path, ROOM), paused=True, noise="off"))
    path = bad_program(tmp_path)

    async def body(pilot: Pilot) -> None:
        dialog = await load(pilot, path)
        assert app.station.program is None
        problems = str(dialog.query_one("#alg-problems", Static).render())
        assert problems.count("state.missing") == 12
        assert f"{path}: panel Main: activity" in problems
        assert "12 problems" in str(dialog.query_one("#alg-title", Static).render())
        details = dialog.query_one("#alg-details")
        assert details.max_scroll_y > 0  # more than fits: it scrolls
        # the app still works: a built-in can be chosen and started
        await dialog.choose("right-wall")
        assert app.station.algorithm is not None

    run(app, body)


def test_a_served_student_loads_programs_only_from_the_workspace(tmp_path):
    workspace = tmp_path / "ws"
    workspace.mkdir()
    drive_by_wire(workspace, "mine.viple")
    outside = drive_by_wire(tmp_path, "theirs.viple")
    app = make_app(
        AppSettings(maze_file(tmp_path, ROOM), paused=True, noise="off", workspace=workspace)
    )

    async def body(pilot: Pilot) -> None:
        dialog = await load(pilot, outside)
        assert app.station.program is None
        error = str(dialog.query_one("#alg-error", Static).render())
        assert "workspace" in error or "outside" in error
        await dialog.choose("~/mine.viple")
        assert app.station.program is not None
        assert app.station.program.source == "~/mine.viple"

    run(app, body)


def test_a_program_lacking_a_sensor_cannot_start_and_says_which(tmp_path):
    app = make_app(AppSettings(maze_file(tmp_path, ROOM), paused=True, noise="off"))
    b = ProgramBuilder()
    main = b.panel("Main")
    b.robot(main)
    main.chain(main.add(22, "Robot/IoT Controller 0", "7"), main.add(28, ""))
    path = b.write(tmp_path / "touchy.viple")

    async def body(pilot: Pilot) -> None:
        dialog = await load(pilot, path)
        missing = str(dialog.query_one("#alg-missing", Static).render())
        assert "it reads port 7, but the robot has no sensor there" in missing
        await pilot.click("#alg-start")
        await pilot.pause()
        assert isinstance(app.screen, AlgorithmModal)
        assert "cannot start" in str(dialog.query_one("#alg-error", Static).render())
        assert app.station.driving is None

    run(app, body)


def screen_keys(program: str, tmp_path) -> str:
    """Answers p, r and space (keys the main screen uses) by printing them."""
    b = ProgramBuilder()
    main = b.panel("Main")
    b.robot(main)
    for number in (15, 17, 59):  # p, r, space
        main.chain(main.add(13, str(number)), main.add(2, '"got " + value'), main.add(28, ""))
    return b.write(tmp_path / program)


def active_actions(app) -> set[str]:
    """The actions of the keys the footer shows."""
    return {b.binding.action for b in app.screen.active_bindings.values() if b.binding.show}


def test_ctrl_k_sends_every_key_to_the_program_until_pressed_again(tmp_path):
    app = make_app(AppSettings(maze_file(tmp_path, ROOM), paused=True, noise="off"))
    path = screen_keys("keys.viple", tmp_path)

    async def body(pilot: Pilot) -> None:
        station = app.station
        await load(pilot, path)
        await pilot.press("escape")
        await pilot.press("ctrl+k")  # no program runs yet: nothing happens
        assert not app.screen.takes_all_keys
        await pilot.press("x")
        run_ = station.driving.controller
        station.pause()
        # p is the workbench's: it resumes the simulation, and the program never sees it
        await pilot.press("p")
        assert not station.paused
        station.pause()
        await pilot.press("ctrl+k")
        await pilot.pause()
        assert app.screen.takes_all_keys
        assert active_actions(app) == {"keys_back", "quit"}  # the footer: ^k back, ^q quit
        panel = app.screen.query_one(ProgramState)
        assert "ALL KEYS go to it" in str(panel.query_one("#program-summary", Static).render())
        for key in ("p", "r", "space", "R", "ctrl+p", "tab", "question_mark"):
            await pilot.press(key)
            station.step(2)
        assert station.paused and station.driving.controller is run_  # nothing of the workbench ran
        assert app.screen is app.screen_stack[-1] and len(app.screen_stack) == 1
        app.refresh_views()
        await pilot.pause()
        got = [line.split(None, 1)[1] for line in panel.console_lines]
        assert got == ["got p", "got r", "got space", "got r"]  # R is the r key
        await pilot.press("ctrl+k")  # the keys come back
        assert not app.screen.takes_all_keys and "pause" in active_actions(app)
        await pilot.press("space")  # space stops the program again
        assert station.driving is None

    run(app, body)


def test_all_keys_end_when_the_program_stops(tmp_path):
    app = make_app(AppSettings(maze_file(tmp_path, ROOM), paused=True, noise="off"))
    path = screen_keys("keys.viple", tmp_path)

    async def body(pilot: Pilot) -> None:
        station = app.station
        await load(pilot, path)
        await pilot.press("escape", "x", "ctrl+k")
        assert app.screen.takes_all_keys
        station.stop("stopped")  # e.g. a lab's set-up changes the controller
        app.refresh_views()
        await pilot.pause()
        assert not app.screen.takes_all_keys
        paused = station.paused
        await pilot.press("p")  # p is the workbench's again
        assert station.paused is not paused
        assert "keys_back" not in active_actions(app) and "pause" in active_actions(app)

    run(app, body)


def test_after_loading_a_program_f_fits_the_sensors_its_diagram_reads(tmp_path):
    from workbench.sim.sensors import SensorSpec

    app = make_app(AppSettings(maze_file(tmp_path, ROOM), paused=True, noise="off"))
    path = drive_by_wire(tmp_path)

    async def body(pilot: Pilot) -> None:
        station = app.station
        station.apply_sensors([SensorSpec("touch", 1, "right")])  # port 1 is not a distance
        await pilot.press("g")
        await pilot.pause()
        field = app.screen.query_one("#alg-path", Input)
        field.focus()
        field.value = path
        await pilot.press("enter")  # loads the program; the path is done with
        await pilot.pause()
        assert not field.has_focus
        await pilot.press("f")
        await pilot.pause()
        assert field.value == path  # f acted on the dialog, not on the path
        assert [str(s) for s in station.sensors] == ["distance:1:right"]
        assert station.program.needs(station.sensors) is None
        await pilot.press("f")  # nothing more to fit: it says so
        await pilot.pause()
        said = str(app.screen.query_one("#alg-error", Static).render())
        assert said == "the robot has the sensors wire.viple reads already"

    run(app, body)


def test_a_program_is_read_and_checked_beside_the_event_loop(tmp_path, monkeypatch):
    import asyncio
    import threading

    import workbench.tui.dialogs.algorithm as dialog_module

    app = make_app(AppSettings(maze_file(tmp_path, ROOM), paused=True, noise="off"))
    path = drive_by_wire(tmp_path)
    release = threading.Event()
    checking = threading.Event()
    real_load = dialog_module.load_choice

    def slow_load(station, typed):  # a file that takes long to check
        checking.set()
        assert release.wait(30)
        return real_load(station, typed)

    monkeypatch.setattr(dialog_module, "load_choice", slow_load)

    async def body(pilot: Pilot) -> None:
        await pilot.press("g")
        await pilot.pause()
        dialog = pilot.app.screen
        assert isinstance(dialog, AlgorithmModal)
        choosing = asyncio.create_task(dialog.choose(path))
        while not checking.is_set():
            await pilot.pause(0.01)
        await pilot.pause()  # the app answers while the file is checked
        assert "loading" in str(dialog.query_one("#alg-error", Static).render())
        assert app.station.program is None
        release.set()
        assert await choosing
        assert app.station.program is not None and app.station.program.name == "wire.viple"

    run(app, body)


def test_f_on_the_main_screen_fits_the_chosen_program_not_the_algorithm_before_it(tmp_path):
    from tests.app.support import said
    from workbench.sim.sensors import SensorSpec

    app = make_app(AppSettings(maze_file(tmp_path, ROOM), paused=True, noise="off"))
    path = drive_by_wire(tmp_path)

    async def body(pilot: Pilot) -> None:
        station = app.station
        station.select_algorithm("right-wall")  # chosen first, then the program file
        await load(pilot, path)
        await pilot.press("escape")
        station.apply_sensors([SensorSpec("touch", 1, "right")])  # port 1 is not a distance
        await pilot.press("f")
        await pilot.pause()
        assert said(app) == "sensors set for wire.viple: distance:1:right; x starts it"
        assert station.program.needs(station.sensors) is None
        await pilot.press("f")
        assert said(app) == "the sensors already fit wire.viple"

    run(app, body)
