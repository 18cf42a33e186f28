"""Driving keys taken at once (a served session's typed keys, without key events) do what the
same keys do as key events, only where Textual would run the same action; and a screen's change
is drawn in the wake that made it, at most at Textual's frame rate."""

from __future__ import annotations

import asyncio
from time import monotonic

import pytest
from textual import events
from textual.pilot import Pilot
from textual.widgets import Tooltip

from tests.app.support import maze_file, run, run_panel
from tests.waiting import until
from workbench.tui.app import WorkbenchApp, make_app
from workbench.tui.dialogs.help import HelpScreen
from workbench.tui.screens.main import MainScreen
from workbench.tui.widgets.run_status import RunStatus
from workbench.wire.settings import AppSettings

ROOM = "#######\n#.....#\n#..S..#\n#.....#\n#######\n"


def heading(app: WorkbenchApp) -> float:
    app.station.step(60 * 4)
    return app.station.snapshot().pose.heading


async def ready(app: WorkbenchApp) -> MainScreen:
    """Wait until the main screen is on top with nothing queued on a key's way (the clock's
    tick, a refresh): under load that can take a few turns after the app starts or a key."""
    return await until(
        lambda: (
            isinstance(app.screen, MainScreen)
            and not app.keys_on_their_way
            and app.screen.nothing_on_the_way()
            and app.screen
        ),
        "the main screen ready to take a key at once",
    )


async def take(app: WorkbenchApp, key: str) -> None:
    """Offer ``key`` as typed once the app is ready for it; it must be taken at once."""
    await ready(app)
    assert app.take_typed_key(key), f"{key!r} not taken at once"


def test_a_driving_key_taken_at_once_drives_as_its_key_event_does(tmp_path):
    app = make_app(AppSettings(maze_file(tmp_path, ROOM), paused=True, noise="off"))

    async def body(pilot: Pilot) -> None:
        await take(app, "d")
        assert heading(app) == pytest.approx(90, abs=0.5)
        await pilot.press("d")
        assert heading(app) == pytest.approx(180, abs=0.5)
        await take(app, "p")  # resume: the clock runs the robot in real time
        await pilot.pause()
        assert "running" in run_panel(app)
        await take(app, "p")
        await pilot.pause()
        assert "PAUSED" in run_panel(app)

    run(app, body)


def test_keys_whose_binding_is_not_a_quick_action_come_as_key_events(tmp_path):
    app = make_app(AppSettings(maze_file(tmp_path, ROOM), paused=True, noise="off"))
    assert not app.take_typed_key("w")  # no screen yet (as while the app starts or ends)

    async def body(pilot: Pilot) -> None:
        await ready(app)
        assert not app.take_typed_key("e")  # opens the editor: a key event does that
        assert not app.take_typed_key("x")  # bound to nothing
        assert isinstance(app.screen, MainScreen)
        app.set_keymap({"drive.right": "l"})  # the keymap moves the binding, and the quick key
        await ready(app)
        assert not app.take_typed_key("d")
        assert heading(app) == pytest.approx(0, abs=0.5)
        await take(app, "l")
        assert heading(app) == pytest.approx(90, abs=0.5)

    run(app, body)


def test_no_key_is_taken_at_once_over_a_dialog_or_while_a_key_before_it_is_on_its_way(tmp_path):
    app = make_app(AppSettings(maze_file(tmp_path, ROOM), paused=True, noise="off"))

    async def body(pilot: Pilot) -> None:
        await pilot.press("question_mark")
        assert isinstance(app.screen, HelpScreen)
        assert not app.take_typed_key("d")
        await pilot.press("escape")
        await ready(app)
        # a key typed before, still queued for the app: the next waits its turn behind it
        app.post_message(events.Key("a", "a"))
        assert not app.take_typed_key("d")
        await pilot.pause()
        assert heading(app) == pytest.approx(270, abs=0.5)  # the queued 'a' turned left
        await take(app, "d")
        turned = heading(app) % 360
        assert min(turned, 360 - turned) < 0.5  # and back to where it started

    run(app, body)


def test_a_quick_key_is_refused_where_the_screen_refuses_its_action(tmp_path):
    app = make_app(AppSettings(maze_file(tmp_path, ROOM), paused=True, noise="off"))

    async def body(pilot: Pilot) -> None:
        screen = await ready(app)
        refused = {"drive"}
        checked = screen.check_action
        screen.check_action = lambda action, params: (  # type: ignore[method-assign]
            False if action in refused else checked(action, params)
        )
        assert not app.take_typed_key("d")
        await take(app, "p")

    run(app, body)


def test_a_change_is_drawn_at_once_and_the_next_within_a_frame_waits_for_the_timer(tmp_path):
    app = make_app(AppSettings(maze_file(tmp_path, ROOM), paused=True, noise="off"))

    async def body(pilot: Pilot) -> None:
        screen = await ready(app)
        await pilot.pause(0.1)
        resumed = []
        timer = screen._update_timer
        resume = timer.resume
        timer.resume = lambda: (resumed.append(monotonic()), resume())[1]  # type: ignore[method-assign]
        screen._frame_at = drawn = monotonic() - 1  # the last frame a second ago
        await take(app, "p")
        await pilot.pause()
        assert screen._frame_at > drawn and not resumed  # drawn in the same wake, no timer
        assert "running" in app.screen.query_one(RunStatus).lines[1]
        screen._frame_at = monotonic() + 60  # as if a frame had just been drawn
        await take(app, "p")
        await pilot.pause()
        assert resumed  # within a frame period of the last: the timer draws it

    run(app, body)


def test_a_quick_key_clears_a_tooltip_as_a_key_event_does(tmp_path):
    app = make_app(AppSettings(maze_file(tmp_path, ROOM), paused=True, noise="off"))

    async def go() -> None:
        async with app.run_test(size=(80, 24), tooltips=True) as pilot:
            screen = app.screen
            await pilot.hover("#maze", offset=(3, 2))
            # the maze view's tooltip, shown where the mouse rests after Textual's delay
            tips = await until(
                lambda: [c for c in screen.children if isinstance(c, Tooltip) and c.display],
                "the maze view's tooltip",
            )
            # taken as soon as nothing before it is still on its way (the hover's own events)
            await until(lambda: app.take_typed_key("d"), "the quick key taken")
            await pilot.pause()
            assert not tips[0].display

    asyncio.run(go())
