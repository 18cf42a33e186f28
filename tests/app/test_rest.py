"""The app at rest: while nothing moves its clock ticks once a second and it draws nothing new
but the time; a key wakes it, after the time owed at rest has run, so the robot moves from the
moment of the key on."""

from __future__ import annotations

import asyncio
import math
import re

import pytest
from textual.pilot import Pilot
from textual.screen import ModalScreen

from tests.app.support import maze_file, run
from tests.waiting import until
from workbench.tui.app import REST_HZ, make_app
from workbench.tui.widgets.run_status import RunStatus
from workbench.wire.settings import AppSettings

ROOM = "#########\n#.......#\n#...S...#\n#.......#\n#########\n"


def shown_time(app, screen=None) -> float:
    clock = str((screen or app.screen).query_one(RunStatus).lines[1])  # running at 1x | t 2.3 s
    return float(re.search(r" t ([0-9.]+) s", clock).group(1))


def test_an_idle_app_draws_about_once_a_second_and_its_clock_still_runs(tmp_path):
    app = make_app(AppSettings(maze_file(tmp_path, ROOM), noise="off"))

    async def body(pilot: Pilot) -> None:
        await until(lambda: app._resting, "the app at rest")  # nothing moves: REST_HZ ticks
        loop = asyncio.get_running_loop()
        frames, t0, start = app.frames, app.station.session.world.time, loop.time()
        await until(lambda: app.frames >= frames + 2, "two frames at rest")
        t1, elapsed = app.station.session.world.time, loop.time() - start
        # a rest period between them at least (at 20 Hz two frames would take 0.1 s)
        assert elapsed >= 0.9 / REST_HZ
        # simulated time goes on, in real time (t0 is the time of the tick before ``start``)
        assert 0 < t1 - t0 <= elapsed + 1 / REST_HZ
        assert shown_time(app) == pytest.approx(t1, abs=0.051)

    run(app, body)


def test_a_key_wakes_the_app_after_the_time_owed_at_rest_has_run(tmp_path):
    app = make_app(AppSettings(maze_file(tmp_path, ROOM), noise="off"))
    station = app.station
    world = station.session.world
    at_key: list[tuple[float, float, float]] = []  # simulated time and pose as the key acts
    key = station.key

    def noting_key(name: str) -> bool:
        at_key.append((world.time, world.pose.x, world.pose.y))
        return key(name)

    station.key = noting_key  # type: ignore[method-assign]

    async def body(pilot: Pilot) -> None:
        await until(lambda: app._resting, "the app at rest")
        start = world.pose
        rested_from = world.time
        await asyncio.sleep(0.8)  # time owed at rest: up to a second since the last rest tick
        await pilot.press("w")
        assert not app._resting
        (t_key, x_key, y_key) = at_key[0]
        # the clock was brought up to the key before the key acted, the robot standing still
        assert t_key >= rested_from + 0.7
        assert (x_key, y_key) == (start.x, start.y)
        await until(lambda: world.time >= t_key + 0.3, "the robot driving a while")
        moved = math.hypot(world.pose.x - start.x, world.pose.y - start.y)
        # it moved from the key on, never for the time it stood still before it
        speed = station.session.profile.move_speed
        assert 0 < moved <= speed * (world.time - t_key) + 0.05
        await pilot.press("space")
        await until(lambda: app._resting, "the app at rest again")

    run(app, body)


def test_paused_the_app_rests_and_p_wakes_it(tmp_path):
    app = make_app(AppSettings(maze_file(tmp_path, ROOM), paused=True))

    async def body(pilot: Pilot) -> None:
        await until(lambda: app._resting, "the app at rest")
        await pilot.press("w")  # motors on, but paused: nothing moves, still at rest
        await pilot.pause()
        assert app._resting
        await pilot.press("p")
        await until(lambda: not app._resting, "the app awake")
        await until(lambda: "running" in str(app.screen.query_one(RunStatus).lines[1]))

    run(app, body)


def test_at_rest_no_time_passes_under_a_dialog_and_the_screen_below_is_not_redrawn(tmp_path):
    # a dialog over the main screen (here the sensor ports), the student reading it
    app = make_app(AppSettings(maze_file(tmp_path, ROOM), noise="off", student="ann"))

    async def body(pilot: Pilot) -> None:
        await pilot.pause(0.3)
        main = app.screen
        await pilot.press("o")
        await pilot.pause(0.3)
        assert app._resting and isinstance(app.screen, ModalScreen)
        shown, lines = shown_time(app, main), list(main.query_one(RunStatus).lines)
        held = app.station.session.world.time
        await pilot.pause(1.5 / REST_HZ)
        # nothing moves: no time passes behind the dialog (a run's time is not the time spent
        # reading it), and the covered screen is not redrawn
        assert app.station.session.world.time == held
        assert shown_time(app, main) == shown
        assert list(main.query_one(RunStatus).lines) == lines
        closed = asyncio.get_running_loop().time()
        await pilot.press("escape")  # the dialog closes: the clock is right when seen
        await pilot.pause(0.2)
        assert app.screen is main
        # (the key woke the clock: for a moment it ticks at full rate, the panel at 4 Hz)
        assert shown_time(app) == pytest.approx(app.station.session.world.time, abs=0.3)
        # at 1x the clock went on by no more than the time since the dialog closed (on a busy
        # machine more than the 0.2 s asked for), never by the seconds it was open
        since = asyncio.get_running_loop().time() - closed
        assert shown_time(app) - held <= since + 0.3

    run(app, body)
