"""The side panels' titles at 80×24: an algorithm's name is drawn whole, even where the panel
has no room for "Algorithm" beside it."""

from __future__ import annotations

import pytest
from textual.pilot import Pilot

from workbench.tui.app import make_app
from workbench.tui.widgets.algorithm_state import AlgorithmState
from workbench.wire.settings import AppSettings

from .support import run, screen_lines


@pytest.mark.parametrize(
    ("name", "title"),
    [
        ("right-wall", "Algorithm right-wall"),
        ("two-distance-local-best", "two-distance-local-best"),
    ],
)
def test_the_algorithm_panel_names_the_algorithm_whole(tmp_path, name, title):
    app = make_app(AppSettings(paused=True, student="ana", data_dir=tmp_path / "data"))

    async def body(pilot: Pilot) -> None:
        app.station.select_algorithm(name)
        app.screen.refresh_views()
        await pilot.pause()
        await pilot.pause()
        panel = app.screen.query_one(AlgorithmState)
        assert str(panel.border_title) == title
        row = screen_lines(app)[panel.region.y]
        assert f"-{title}-" in row, row

    run(app, body)
