"""The transition log's lines, scroll bar and scrolling as entries arrive, in a host of its own."""

from __future__ import annotations

import functools

from textual.app import App, ComposeResult
from textual.containers import Vertical
from textual.geometry import Offset, Region
from textual.scrollbar import ScrollBar
from textual.strip import Strip
from textual.widget import Widget
from textual.widgets import Log

import workbench.tui.plain  # noqa: F401  (the workbench's scroll bar renderer, with its ASCII mode)
from tests.app.support import screen_lines, sync
from workbench.fsm.machine import Transition
from workbench.tui.widgets.log_scroll_bar import LogScrollBar
from workbench.tui.widgets.transition_log import TransitionLog


class Host(App):
    CSS = "Vertical { height: 6; width: 40; }"

    def compose(self) -> ComposeResult:
        with Vertical():
            yield TransitionLog()


def transitions(n: int) -> list[Transition]:
    return [
        Transition(float(i), f"S{i}", f"S{i + 1}", "front < 0.3", {"front": 0.25}) for i in range(n)
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


def textuals_lines(widget: Widget, crop: Region) -> list[Strip]:
    """``widget``'s lines of ``crop`` drawn Textual's way: its styles cache over its class's
    Textual base's ``render_line`` (Textual's ``Log`` for the log, its ``ScrollBar`` for the
    bar), nothing kept from before."""
    base = Log if isinstance(widget, Log) else ScrollBar
    widget._styles_cache.clear()
    widget.refresh()
    widget.render_line = functools.partial(base.render_line, widget)  # type: ignore[method-assign]
    try:
        return Widget.render_lines(widget, crop)
    finally:
        del widget.render_line


def crops(widget: Widget) -> list[Region]:
    width, height = widget.outer_size
    return [
        Region(0, 0, width, height),
        Region(0, 1, width, 2),
        Region(2, 0, width - 5, height),
    ]


@sync
async def test_the_lines_drawn_are_the_ones_textuals_log_and_scroll_bar_draw():
    app = Host()
    async with app.run_test(size=(60, 12)) as pilot:
        log = app.query_one(TransitionLog)
        log.show(object(), transitions(12), "m", False)
        log.write_lines(["\ttabbed\x01 entry", "a line wider than the log, cut at its edge: " * 2])
        await pilot.pause()
        await pilot.pause()
        bar = log.vertical_scrollbar
        assert isinstance(bar, LogScrollBar)
        for step in ("end", "top", "middle", "hover", "grabbed", "focus", "ascii"):
            if step == "top":
                log.scroll_home(animate=False)
            elif step == "middle":
                log.scroll_to(y=5, animate=False)
            elif step == "hover":
                bar.mouse_over = True
            elif step == "grabbed":
                bar.grabbed = Offset(0, 1)
            elif step == "focus":
                bar.grabbed = None
                bar.mouse_over = False
                log.focus()
            elif step == "ascii":
                app.add_class("-ascii")
            await pilot.pause()
            for widget in (log, bar):
                for crop in crops(widget):
                    drawn = widget.render_lines(crop)
                    assert drawn == textuals_lines(widget, crop), (step, widget, crop)
        # styled with padding, the log and its bar are drawn Textual's way
        log.styles.padding = (0, 1)
        bar.styles.padding = (0, 0, 0, 0)
        await pilot.pause()
        crop = Region(0, 0, *log.outer_size)
        assert log.render_lines(crop) == textuals_lines(log, crop)


@sync
async def test_the_log_keeps_its_lines_through_a_resize_and_scrolls_back_by_hand():
    app = Host()
    async with app.run_test(size=(60, 12)) as pilot:
        log = app.query_one(TransitionLog)
        run = object()
        every = transitions(30)
        log.show(run, every[:20], "m", False)
        await pilot.pause()
        await pilot.pause()
        lines = list(log.lines)

        def shown() -> list[str]:
            top = log.region.y
            return [row[: log.scrollable_content_region.width].rstrip()
                    for row in screen_lines(app)[top : top + log.size.height]]  # fmt: skip

        height = log.scrollable_content_region.height
        assert shown() == lines[-height:]
        await pilot.resize_terminal(50, 16)
        await pilot.pause()
        await pilot.pause()
        assert list(log.lines) == lines
        assert shown() == lines[-height:]
        log.show(run, every[:21], "m", False)  # the newest at the bottom, the rest a line up
        await pilot.pause()
        await pilot.pause()
        lines = list(log.lines)
        assert shown() == lines[-height:]
        log.focus()
        for _ in range(3):
            await pilot.press("up")
        await pilot.pause()
        assert log.scroll_y == log.max_scroll_y - 3
        assert shown() == lines[-height - 3 : -3]


@sync
async def test_a_new_entry_draws_the_log_once_scrolled_to_it(monkeypatch):
    # (it scrolled after the next refresh: the log was drawn as it was, then again scrolled)
    app = Host()
    async with app.run_test(size=(60, 12)) as pilot:
        log = app.query_one(TransitionLog)
        run = object()
        every = transitions(30)
        log.show(run, every[:20], "m", False)
        for _ in range(3):
            await pilot.pause()
        drawn: list[list[str]] = []
        render_lines = TransitionLog.render_lines

        def counted(widget: TransitionLog, crop: Region) -> list[Strip]:
            lines = render_lines(widget, crop)
            drawn.append([line.text.rstrip() for line in lines])
            return lines

        monkeypatch.setattr(TransitionLog, "render_lines", counted)
        for n in range(21, 26):
            drawn.clear()
            log.show(run, every[:n], "m", False)
            for _ in range(3):
                await pilot.pause()
            assert len(drawn) == 1, n
            assert drawn[0][-1].startswith(f"{n - 1:6.1f} S{n - 1} -> S{n}"), drawn
