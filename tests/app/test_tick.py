"""The check box of the sign-off dialog reads the same on every terminal."""

from __future__ import annotations

from textual.app import App
from textual.pilot import Pilot

from workbench.tui.widgets.tick import Tick

from .support import run


def test_a_tick_box_reads_ticked_or_not_in_plain_characters():
    class Host(App[None]):
        def compose(self):
            yield Tick("Override", id="tick")

    async def body(pilot: Pilot) -> None:
        tick = pilot.app.query_one(Tick)
        assert str(tick.render()).startswith("[ ]")
        await pilot.click(Tick)
        assert tick.value and str(tick.render()).startswith("[X]")

    run(Host(), body)
