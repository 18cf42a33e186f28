"""Every screen's key bar at 80, 100 and 132 columns: whole keys, none over another, and at
80 columns the keys a newcomer needs first."""

from __future__ import annotations

import pytest
from textual.pilot import Pilot
from textual.widgets._footer import FooterKey

from tests.waiting import until
from workbench.tui.app import make_app
from workbench.tui.screens.editor import EditorScreen
from workbench.tui.screens.labs import LabsScreen
from workbench.tui.screens.main import MainScreen
from workbench.tui.screens.replay import ReplayScreen
from workbench.tui.screens.runs import RunsScreen
from workbench.tui.widgets.key_bar import KeyBar
from workbench.wire.settings import AppSettings

from .support import run, screen_lines

#: what the main screen's bar shows at any width: labs, editor, runs, load maze, help
NEWCOMER = ("l Labs", "e Editor", "R Runs", "m Maze", "? Help")


async def bar_keys(pilot: Pilot) -> list[str]:
    """The keys the bar shows, as "key label", checked against the terminal's last row: each
    drawn whole, in order, none over another, all inside the width. (Once the bar is laid
    out: on a busy machine the screen may not have had its first layout yet.)"""
    app = pilot.app
    bar = app.screen.query_one(KeyBar)

    def laid_out() -> list[FooterKey]:
        keys = list(bar.query(FooterKey))
        return keys if keys and all(k.region.height for k in keys) else []

    keys = await until(laid_out, "the key bar laid out")
    row = screen_lines(app)[-1]
    assert len(row) <= app.size.width
    texts = [f"{k.key_display} {k.description}" for k in keys]
    at = 0
    for key, text in zip(keys, texts, strict=True):
        region = key.region
        assert region.y == app.size.height - 1 and region.right <= app.size.width, text
        assert region.x >= at, f"{text!r} drawn over the key before it"
        assert row[region.x : region.x + len(text)] == text
        at = region.right
    return texts


@pytest.mark.parametrize("width", [80, 100, 132])
def test_every_screens_key_bar_fits_whole(tmp_path, width):
    app = make_app(AppSettings(paused=True, student="ana", record_dir=tmp_path / "runs"))

    async def body(pilot: Pilot) -> None:
        station = app.station
        station.select_algorithm("right-wall")
        station.apply_algorithm_preset()
        station.start()
        station.step(60)
        station.stop()  # one recorded run, for the replay
        assert isinstance(app.screen, MainScreen)
        shown = await bar_keys(pilot)
        assert all(key in shown for key in NEWCOMER), shown
        walked = []
        for key, screen in (("l", LabsScreen), ("e", EditorScreen), ("R", RunsScreen)):
            await pilot.press("escape") if walked else None
            await pilot.pause()
            await pilot.press(key)
            await pilot.pause()
            assert isinstance(app.screen, screen)
            shown = await bar_keys(pilot)
            assert any(k.endswith(("Back", "Close")) for k in shown), shown
            walked.append(screen)
        await pilot.press("enter")
        await pilot.pause()
        assert isinstance(app.screen, ReplayScreen)
        assert "esc Back" in await bar_keys(pilot)

    run(app, body, size=(width, 24))


def test_the_bar_follows_the_terminals_width(tmp_path):
    app = make_app(AppSettings(paused=True, student="ana"))

    async def body(pilot: Pilot) -> None:
        wide = await bar_keys(pilot)
        assert "n Step" in wide
        await pilot.resize_terminal(80, 24)
        await pilot.pause()
        await pilot.pause()
        narrow = await bar_keys(pilot)
        assert "n Step" not in narrow and all(key in narrow for key in NEWCOMER)

    run(app, body, size=(160, 24))
