"""The transition log's scroll bar and scrolling as entries arrive, in a host of its own."""

from __future__ import annotations

from textual.app import App, ComposeResult
from textual.containers import Vertical

from tests.app.support import sync
from workbench.fsm.machine import Transition
from workbench.tui.widgets.transition_log import TransitionLog


class Host(App):
    CSS = "Vertical { height: 6; width: 40; }"

    def compose(self) -> ComposeResult:
        with Vertical():
            yield TransitionLog()


def transitions(n: int) -> list[Transition]:
    return [
        Transition(float(i), f"S{i}", f"S{i + 1}", "front < 0.3", {"front": 0.25})
        for i in range(n)
    ]


@sync
async def test_each_new_entry_moves_the_scroll_bar_and_keeps_the_newest_in_sight():
    app = Host()
    async with app.run_test(size=(60, 12)) as pilot:
        log = app.query_one(TransitionLog)
        run = object()
        every = transitions(25)  # a run's history grows: the same entries, more of them
        log.show(run, every[:3], "m", False)
        await pilot.pause()
        assert log.vertical_scrollbar.window_virtual_size == 3
        for n in (10, 11, 25):
            log.show(run, every[:n], "m", False)
            await pilot.pause()
            await pilot.pause()
            bar = log.vertical_scrollbar
            assert log.line_count == n
            assert bar.window_virtual_size == n, n  # the thumb is sized for every line
            assert log.scroll_y == log.max_scroll_y == n - log.scrollable_content_region.height
            assert bar.position == log.scroll_y
            shown = [log.render_line(y).text for y in range(log.size.height)]
            assert shown[-1].startswith(f"{n - 1:6.1f} S{n - 1} -> S{n}"), shown
