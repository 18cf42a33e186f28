"""The sensor port panel and the algorithm selector, used through the app as a student would."""

from __future__ import annotations

import pytest
from textual.pilot import Pilot
from textual.widgets import Input, OptionList, Select, Static

from tests.app.support import run, said, screen_lines
from workbench.sim.sensors import SensorSpec
from workbench.tui.app import WorkbenchApp, make_app
from workbench.tui.dialogs.algorithm import AlgorithmModal
from workbench.tui.dialogs.sensor_ports import SensorPortsModal
from workbench.tui.screens.main import MainScreen
from workbench.tui.widgets.algorithm_state import AlgorithmState
from workbench.tui.widgets.param_editor import ParamEditor
from workbench.tui.widgets.sensor_readings import SensorReadings
from workbench.tui.widgets.sensor_row_editor import SensorRowEditor
from workbench.tui.widgets.transition_log import TransitionLog
from workbench.wire.settings import AppSettings

ROOM = "#######\n#.....#\n#..S..#\n#.....#\n#######\n"


async def click(pilot: Pilot, selector: str) -> None:
    """Click a button once its last press has finished (a pressed button ignores clicks)."""
    for _ in range(20):
        if not any(w.has_class("-active") for w in pilot.app.screen.query(selector)):
            break
        await pilot.pause(0.05)
    await pilot.click(selector)


def unity_app(tmp_path=None, **kw) -> WorkbenchApp:
    return make_app(AppSettings(paused=True, noise="off", **kw))


def text_of(widget: Static) -> str:
    return str(widget.render())


# -- sensor ports --------------------------------------------------------------------------------


async def open_ports(pilot: Pilot) -> SensorPortsModal:
    await pilot.press("o")
    await pilot.pause()
    screen = pilot.app.screen
    assert isinstance(screen, SensorPortsModal)
    return screen


def row_editors(screen: SensorPortsModal) -> list[SensorRowEditor]:
    return screen.editors


def set_row(editor: SensorRowEditor, port: str | None = None, mount: str | None = None) -> None:
    if port is not None:
        editor.query_one(".row-port", Input).value = port
    if mount is not None:
        editor.query_one(".row-mount", Select).value = mount


def test_the_panel_opens_with_two_distance_sensors_and_a_touch_sensor():
    app = unity_app()

    async def body(pilot: Pilot) -> None:
        screen = await open_ports(pilot)
        rows = screen.rows()
        assert [(r.kind, r.port, r.mount) for r in rows] == [
            ("distance", "1", "right"),
            ("distance", "2", "front"),
            ("touch", "3", None),
        ]
        readings = [str(e.query_one(".row-reading").render()) for e in row_editors(screen)]
        snap = app.station.snapshot()
        assert readings == [f"{snap.readings[1]:.2f}", f"{snap.readings[2]:.2f}", "not mounted"]

    run(app, body)


def test_duplicate_and_out_of_range_ports_are_shown_inline_and_nothing_is_applied():
    app = unity_app()
    before = list(app.station.sensors)

    async def body(pilot: Pilot) -> None:
        screen = await open_ports(pilot)
        first, second, third = row_editors(screen)
        set_row(second, port="1")
        set_row(third, port="120", mount="front")
        await pilot.pause()
        await click(pilot, "#ports-apply")
        await pilot.pause()
        assert first.error == "port 1 is also used by row 2"
        assert second.error == "port 1 is already used by row 1"
        assert third.error == "port 120 is out of range (0-99)"
        assert all(e.has_class("-invalid") for e in (first, second, third))
        status = text_of(screen.query_one("#ports-status", Static))
        assert status.startswith("nothing applied: 3 rows to fix")
        assert app.station.sensors == before
        set_row(second, port="2")
        set_row(third, port="5")
        await pilot.pause()
        assert [e.error for e in row_editors(screen)] == [None, None, None]

    run(app, body)


def test_a_valid_apply_changes_the_live_robot_and_the_readings_by_port():
    app = unity_app()

    async def body(pilot: Pilot) -> None:
        screen = await open_ports(pilot)
        first, _second, third = row_editors(screen)
        set_row(first, port="7")
        set_row(third, mount="back")
        await pilot.pause()
        first.query_one(".row-port", Input).focus()
        await pilot.press("enter")  # enter in a port field applies
        assert app.station.sensors == [
            SensorSpec("distance", 7, "right"),
            SensorSpec("distance", 2, "front"),
            SensorSpec("touch", 3, "back"),
        ]
        assert set(app.station.snapshot().readings) == {7, 2, 3}
        await pilot.pause()
        assert str(third.query_one(".row-reading").render()) == "free"
        await pilot.press("escape")
        assert isinstance(app.screen, MainScreen)
        lines = app.screen.query_one(SensorReadings).lines
        assert [line.split()[0] for line in lines] == ["2", "3", "7"]
        assert lines[2].split()[1:3] == ["distance", "right"]

    run(app, body)


def test_presets_add_and_remove_rows():
    app = unity_app()

    async def body(pilot: Pilot) -> None:
        screen = await open_ports(pilot)
        await click(pilot, "#preset-web-two-distance")
        await pilot.pause()
        assert app.station.sensors == [SensorSpec("distance", 3, "front")]
        assert [(r.kind, r.port, r.mount) for r in screen.rows()] == [
            ("distance", "3", "front"),
            ("distance", "1", None),
            ("touch", "2", None),
        ]
        await click(pilot, "#preset-web-wall-following")
        await pilot.pause()
        assert app.station.sensors == [
            SensorSpec("distance", 1, "right"),
            SensorSpec("touch", 2, "front"),
        ]
        await click(pilot, "#ports-add")
        await pilot.pause()
        assert len(screen.rows()) == 4 and screen.rows()[-1].port == "4"
        await click(pilot, ".row-remove")
        await pilot.pause()
        assert [r.port for r in screen.rows()] == ["2", "3", "4"]
        assert [e.number for e in row_editors(screen)] == [1, 2, 3]
        await click(pilot, "#ports-apply")
        assert app.station.sensors == [SensorSpec("touch", 2, "front")]

    run(app, body)


# -- algorithms ------------------------------------------------------------------------------------


async def open_algorithms(pilot: Pilot) -> AlgorithmModal:
    await pilot.press("g")
    await pilot.pause()
    screen = pilot.app.screen
    assert isinstance(screen, AlgorithmModal)
    return screen


async def choose_builtin(pilot: Pilot, screen: AlgorithmModal, name: str) -> None:
    options = screen.query_one("#alg-builtins", OptionList)
    options.focus()
    options.highlighted = options.get_option_index(name)
    await pilot.press("enter")
    await pilot.pause()


def test_choosing_shows_description_sensors_and_parameters():
    app = unity_app()

    async def body(pilot: Pilot) -> None:
        screen = await open_algorithms(pilot)
        await choose_builtin(pilot, screen, "right-wall")
        assert app.station.algorithm.name == "right-wall"
        assert text_of(screen.query_one("#alg-title", Static)) == "right-wall  (built-in)"
        assert "Right-wall following" in text_of(screen.query_one("#alg-description", Static))
        sensors = text_of(screen.query_one("#alg-sensors", Static))
        assert "right: distance sensor mounted right, port 1" in sensors
        assert not screen.query_one("#alg-missing").display
        params = {e.parameter.name: e.text for e in screen.query(ParamEditor)}
        assert params["front_blocked"] == "0.9" and params["forward_power"] == "1"

    run(app, body)


def test_start_and_the_state_display_follows_the_engine():
    app = unity_app()
    station = app.station

    async def body(pilot: Pilot) -> None:
        screen = await open_algorithms(pilot)
        await choose_builtin(pilot, screen, "right-wall")
        await click(pilot, "#alg-start")
        await pilot.pause()
        assert isinstance(app.screen, MainScreen)
        assert station.driving is not None and not station.pacer.paused
        station.pacer.paused = True
        state = app.screen.query_one(AlgorithmState)
        seen = set()
        for _ in range(40):
            station.step(60)
            app.refresh_views()
            await pilot.pause()
            assert state.highlighted == station.driving.controller.state
            seen.add(state.highlighted)
        assert len(seen) >= 3
        assert state.summary.startswith(f"in {station.driving.controller.state}")
        last = station.driving.controller.history[-1]
        assert state.last.startswith(f"{last.time:.1f} s {last.source} -> {last.target}")
        log = app.screen.query_one(TransitionLog)
        # each transition is in the log whole: long ones wrap inside the panel, none is cut
        assert log.line_count >= len(station.driving.controller.history)
        width = log.scrollable_content_region.width
        assert all(len(line) <= width for line in log.lines), (width, log.lines)
        logged = " ".join(" ".join(log.lines).split())
        for tr in station.driving.controller.history:
            assert f"{tr.time:.1f} {tr.source} -> {tr.target}" in logged
        assert "driver: algorithm right-wall" in "\n".join(app.screen.query_one("#run").lines)

    run(app, body)


def test_the_last_transition_takes_the_rows_its_text_needs_as_it_grows_and_shrinks():
    """The algorithm panel's lines are laid out again only when one takes another number of
    rows; a line that grows onto a second row still shows whole, and gives the row back."""
    app = unity_app()

    async def body(pilot: Pilot) -> None:
        state = app.screen.query_one(AlgorithmState)
        last = state.query_one("#algorithm-last", Static)
        state.last = "1.0 s a -> b"
        await pilot.pause()
        assert last.size.height == 1
        width = last.content_region.width
        long = "2.0 s forward -> turn when " + " ".join(f"d{i}<0.5" for i in range(width // 3))
        state.last = long
        await pilot.pause()
        rows = last.size.height
        assert rows >= 2
        shown = " ".join(line.strip() for line in screen_lines(app) if line.strip())
        assert "d0<0.5" in shown and f"d{width // 3 - 1}<0.5" in shown  # nothing cut
        state.last = "3.0 s turn -> forward"  # the same rows again: no new layout needed
        await pilot.pause()
        assert last.size.height == 1

    run(app, body)


def test_the_transition_log_follows_the_newest_transitions():
    """However many transitions there are, and however the panel above the log grows or shrinks
    (the last transition's lines come and go), the log shows the newest one at its bottom."""
    app = unity_app()
    station = app.station

    async def body(pilot: Pilot) -> None:
        station.select_algorithm("right-wall")
        await pilot.press("x")
        station.pacer.paused = True
        log = app.screen.query_one(TransitionLog)
        history = station.driving.controller.history
        while len(history) < 12:
            station.step(30)
            app.refresh_views()
            await pilot.pause()
        await pilot.pause()
        assert log.line_count > log.scrollable_content_region.height  # more than it can show
        newest = history[-1]
        shown = " ".join(" ".join(screen_lines(app)).split())
        assert f"{newest.time:.1f} {newest.source} -> " in shown, screen_lines(app)
        assert log.scroll_y == log.max_scroll_y

    run(app, body)


def test_the_algorithm_panel_keeps_its_rows_while_it_runs_and_fits_them_when_paused():
    """Running, a shorter text in the algorithm panel keeps the rows it had (the panel does not
    jump with each shorter transition, and no frame lays the screen out for it): the heights
    change only in a frame where some text needed more rows than it had. Paused, each text
    takes just the rows it needs again."""
    app = unity_app()
    station = app.station

    def rows(widget: Static) -> tuple[int, int]:
        size = widget.size
        width = widget.content_region.width
        return widget.get_content_height(size, size, width), widget.size.height

    async def body(pilot: Pilot) -> None:
        station.select_algorithm("right-wall")
        await pilot.press("x")
        station.pacer.paused = False
        panel = app.screen.query_one(AlgorithmState)
        texts = [panel.query_one(f"#algorithm-{name}", Static) for name in ("summary", "last")]
        kept = [rows(widget)[1] for widget in texts]
        shorter = 0
        history = station.driving.controller.history
        while len(history) < 12:
            station.step(30)
            app.refresh_views()
            await pilot.pause()
            now = [rows(widget) for widget in texts]
            assert all(height >= needed for needed, height in now)
            if not any(needed > was for (needed, _), was in zip(now, kept, strict=True)):
                assert [height for _, height in now] == kept  # no text grew: no layout
            shorter += sum(needed < height for needed, height in now)
            kept = [height for _, height in now]
        assert shorter  # some text did get shorter than the rows it keeps
        await pilot.press("p")
        app.refresh_views()
        await pilot.pause()
        assert station.paused
        for widget in texts:
            needed, height = rows(widget)
            assert height == needed

    run(app, body)


def test_pause_step_and_reset_from_the_dialog():
    app = unity_app()
    station = app.station

    async def body(pilot: Pilot) -> None:
        screen = await open_algorithms(pilot)
        await choose_builtin(pilot, screen, "right-wall")
        await click(pilot, "#alg-start")
        await pilot.pause()
        screen = await open_algorithms(pilot)
        await click(pilot, "#alg-pause")
        assert station.pacer.paused
        t = station.snapshot().time
        await click(pilot, "#alg-step")
        assert station.snapshot().time == pytest.approx(t + station.session.every / 60)
        assert "running, in" in str(screen.query_one("#alg-live").render())
        await click(pilot, "#alg-reset")
        assert station.driving is None and station.snapshot().time == 0
        assert station.runs[-1].ended == "reset"

    run(app, body, size=(120, 40))


def test_x_starts_and_stops_the_chosen_algorithm_from_the_main_screen():
    app = unity_app()
    app.station.select_algorithm("right-wall")

    async def body(pilot: Pilot) -> None:
        await pilot.press("x")
        assert app.station.driving is not None
        await pilot.press("x")
        assert app.station.driving is None
        assert str(app.station.snapshot().driver) == "keys"

    run(app, body)


def test_a_missing_sensor_is_explained_with_a_one_key_fix():
    app = unity_app()
    station = app.station
    station.apply_preset("web-two-distance")
    station.select_algorithm("right-wall")

    async def body(pilot: Pilot) -> None:
        state = app.screen.query_one(AlgorithmState)
        assert "cannot start" in state.summary and "f fits" in state.summary
        await pilot.press("x")
        assert station.driving is None
        assert "f fits the sensors it needs" in said(app)
        await pilot.press("f")
        assert station.missing_sensors() is None
        assert station.sensors == [
            SensorSpec("distance", 1, "right"),
            SensorSpec("distance", 2, "front"),
        ]
        await pilot.press("x")
        assert station.driving is not None

    run(app, body)


def test_the_dialog_explains_a_missing_sensor_and_f_fixes_it():
    app = unity_app()
    app.station.apply_preset("web-two-distance")

    async def body(pilot: Pilot) -> None:
        screen = await open_algorithms(pilot)
        await choose_builtin(pilot, screen, "right-wall")
        missing = screen.query_one("#alg-missing", Static)
        assert missing.display and "needs a distance sensor mounted right" in text_of(missing)
        await click(pilot, "#alg-start")
        assert app.station.driving is None
        assert "press f" in text_of(screen.query_one("#alg-error", Static))
        await pilot.press("f")
        assert app.station.missing_sensors() is None and not missing.display
        await click(pilot, "#alg-start")
        assert app.station.driving is not None

    run(app, body, size=(120, 40))


def test_a_bad_fsm_file_is_reported_with_file_line_and_column(tmp_path):
    bad = tmp_path / "mine.yaml"
    bad.write_text("name: mine\ninitial: Go\nstates:\n  Go:\n    on_enter:\n      - fly: 1\n")
    app = unity_app()

    async def body(pilot: Pilot) -> None:
        screen = await open_algorithms(pilot)
        path = screen.query_one("#alg-path", Input)
        path.value = str(bad)
        path.focus()
        await pilot.press("enter")
        await pilot.pause()
        error = text_of(screen.query_one("#alg-error", Static))
        assert error.startswith(f"{bad}:6:")
        assert app.station.algorithm is None

    run(app, body, size=(120, 40))


def test_a_good_fsm_file_loads(tmp_path):
    good = tmp_path / "mine.yaml"
    good.write_text(
        "name: mine\nsensors:\n  front: {kind: distance, mount: front, port: 2}\n"
        "initial: Go\nstates:\n  Go:\n    on_enter:\n      - move: 1\n"
        "    transitions:\n      - when: front < 1\n        to: Stop\n"
        "  Stop:\n    on_enter:\n      - stop: true\n"
    )
    app = unity_app()

    async def body(pilot: Pilot) -> None:
        screen = await open_algorithms(pilot)
        screen.query_one("#alg-path", Input).value = str(good)
        await click(pilot, "#alg-load")
        await pilot.pause()
        assert app.station.algorithm is not None and app.station.algorithm.name == "mine"
        assert text_of(screen.query_one("#alg-title", Static)) == f"mine  ({good})"
        assert text_of(screen.query_one("#alg-error", Static)) == ""

    run(app, body, size=(120, 40))


def test_parameters_are_checked_as_typed_and_reset_to_defaults():
    app = unity_app()

    async def body(pilot: Pilot) -> None:
        screen = await open_algorithms(pilot)
        await choose_builtin(pilot, screen, "right-wall")
        editor = next(e for e in screen.query(ParamEditor) if e.parameter.name == "forward_power")
        editor.query_one(Input).value = "5"
        await pilot.pause()
        assert editor.invalid
        assert "above its maximum 1" in text_of(editor.query_one(".param-error", Static))
        await click(pilot, "#alg-start")
        assert app.station.driving is None
        assert "forward_power" in text_of(screen.query_one("#alg-error", Static))
        editor.query_one(Input).value = "0.5"
        await pilot.pause()
        assert not editor.invalid and app.station.params()["forward_power"] == 0.5
        await click(pilot, "#alg-defaults")
        await pilot.pause()
        assert app.station.params()["forward_power"] == 1.0
        fresh = next(e for e in screen.query(ParamEditor) if e.parameter.name == "forward_power")
        assert fresh.text == "1"

    run(app, body, size=(120, 40))


def test_a_failing_algorithm_stops_with_its_reason_on_the_message_line(tmp_path):
    failing = tmp_path / "failing.yaml"
    failing.write_text(
        "name: failing\nsensors:\n  front: {kind: distance, mount: front, port: 2}\n"
        "initial: Go\nstates:\n  Go:\n    transitions:\n"
        "      - when: 1 / (front - front) > 0\n        to: Go\n"
    )
    app = unity_app()
    app.station.select_algorithm(failing)

    async def body(pilot: Pilot) -> None:
        await pilot.press("x")
        await pilot.pause(0.3)
        assert app.station.driving is None
        message = app.screen.query_one("#message").message
        assert message.startswith("algorithm stopped: failing, state Go")

    run(app, body)


def test_the_message_line_follows_what_the_student_does(tmp_path):
    app = unity_app()
    station = app.station

    async def body(pilot: Pilot) -> None:
        await pilot.press("g")
        assert isinstance(app.screen, AlgorithmModal)
        await pilot.press("enter")  # the first built-in: right-wall
        await pilot.pause()
        assert said(app) == "chose right-wall: Start (or x) runs it"
        await pilot.press("escape", "x")
        await pilot.pause()
        assert station.driving is not None and said(app) == ""
        await pilot.press("x")
        assert said(app) == "algorithm stopped: the keys drive"
        await pilot.press("r")
        assert said(app) == ""

    run(app, body)


def test_a_long_message_wraps_onto_more_rows_and_back(tmp_path):
    app = unity_app()
    long = (
        "cannot start: programs/right-wall.viple: panel Main: activity 20 (kind 22, Robot "
        "Touch Sensor): it reads port 2, but the robot has distance:2:front there"
    )

    async def body(pilot: Pilot) -> None:
        main = app.screen
        assert isinstance(main, MainScreen)
        main.say(long)
        await pilot.pause()
        shown = " ".join(" ".join(screen_lines(app)).split())
        assert "it reads port 2, but the robot has distance:2:front there" in shown
        main.say("paused")
        await pilot.pause()
        assert app.screen.query_one("#message").size.height == 1

    run(app, body)
