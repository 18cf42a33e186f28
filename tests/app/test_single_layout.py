"""A screen laid out once per change (``SingleLayout``): what a layout changes still shows, the
scroll bars of what grows and shrinks still come and go and scroll, and what the layout
resized is drawn once, in the layout's frame."""

from __future__ import annotations

import asyncio
from typing import Any

import pytest
from textual.app import App, ComposeResult
from textual.containers import Horizontal, VerticalScroll
from textual.geometry import Region
from textual.screen import Screen
from textual.strip import Strip
from textual.widget import Widget
from textual.widgets import Log, Static

from tests.app.support import sync
from tests.waiting import until
from workbench.tui.serving.compositor import use_live_compositor
from workbench.tui.serving.single_layout import VIRTUAL_SIZE, SingleLayout


class Panels(Screen[None]):
    """A line of text whose rows change, a list that grows, and a log taller than its box,
    drawn as the main screen is (Textual's compositor draws every widget beside a change)."""

    DEFAULT_CSS = """
    #text { height: auto; width: 20; }
    #list { height: 5; width: 20; }
    #list > Static { height: 1; }
    #grows { height: 4; width: 20; }
    #grows > Static { height: auto; }
    Log { height: 4; width: 20; }
    """

    def __init__(self) -> None:
        super().__init__()
        use_live_compositor(self)

    def compose(self) -> ComposeResult:
        with Horizontal():
            yield Static("one row", id="text")
            yield VerticalScroll(id="list")
            with VerticalScroll(id="grows"):
                yield Static("a", id="inner")
            yield Log()


class SingleLayoutPanels(Panels, SingleLayout):
    pass


class Host(App[None]):
    def __init__(self, screen: Screen[None]) -> None:
        super().__init__()
        self.under_test = screen

    def on_mount(self) -> None:
        self.push_screen(self.under_test)


class Counted:
    """How often the screen was laid out whole, and how often each widget was drawn."""

    def __init__(self, screen: Screen[Any]) -> None:
        self.layouts = 0
        self.drawn: dict[Widget, int] = {}
        layout = screen._refresh_layout

        def counted_layout(size: Any = None, scroll: bool = False) -> None:
            if not scroll:
                self.layouts += 1
            layout(size, scroll)

        screen._refresh_layout = counted_layout  # type: ignore[method-assign]

    def watch(self, widget: Widget) -> None:
        render_lines = widget.render_lines

        def counted_render(crop: Region) -> list[Strip]:
            self.drawn[widget] = self.drawn.get(widget, 0) + 1
            return render_lines(crop)

        widget.render_lines = counted_render  # type: ignore[method-assign]


async def settle(app: App[Any]) -> None:
    """Wait until the screen has nothing left to lay out or draw, and stays so a moment (what
    a frame asks for, a widget's redraw, comes after it)."""
    screen = app.screen

    def still() -> bool:
        return not (screen._layout_required or screen._dirty_widgets or screen._repaint_required)

    for _ in range(3):
        await until(still, "the screen laid out and drawn")
        await asyncio.sleep(0.05)
    await until(still, "the screen laid out and drawn")


@pytest.mark.parametrize(("screen_class", "layouts"), [(SingleLayoutPanels, 1), (Panels, 2)])
@sync
async def test_a_widget_whose_rows_change_lays_the_screen_out_once(screen_class, layouts):
    # Textual's own screen lays out a second time (the case SingleLayout is for: when this
    # says 1 for Textual's screen, Textual no longer needs it)
    screen = screen_class()
    app = Host(screen)
    async with app.run_test(size=(80, 12)) as pilot:
        await pilot.pause()
        await settle(app)
        counted = Counted(screen)
        text = screen.query_one("#text", Static)
        text.update("one row\nthree\nrows")
        await until(lambda: text.size.height == 3, "the text three rows high")
        await settle(app)
        assert counted.layouts == layouts
        assert app.screen.get_widget_at(0, 2)[0] is text
        text.update("one row")
        await until(lambda: text.size.height == 1, "the text one row high again")
        await settle(app)
        assert counted.layouts == 2 * layouts
        assert VIRTUAL_SIZE._layout  # a layout over, virtual sizes ask for layouts again


@sync
async def test_a_list_that_grows_gets_its_scroll_bar_scrolls_to_its_end_and_loses_it_again():
    screen = SingleLayoutPanels()
    app = Host(screen)
    async with app.run_test(size=(80, 12)) as pilot:
        await pilot.pause()
        listing = screen.query_one("#list", VerticalScroll)
        await listing.mount_all(Static(f"item {i}") for i in range(3))
        await settle(app)
        assert not listing.show_vertical_scrollbar
        assert listing.query(Static).first().size.width == 20
        await listing.mount_all(Static(f"item {i}") for i in range(3, 12))
        await settle(app)
        assert listing.show_vertical_scrollbar
        assert listing.max_scroll_y == 12 - 5
        bar = listing.vertical_scrollbar
        width = listing.scrollbar_size_vertical
        assert bar.region == Region(listing.region.right - width, listing.region.y, width, 5)
        assert bar.window_virtual_size == 12
        items = list(listing.query(Static))
        assert items[0].size.width == 20 - bar.size.width  # the bar takes its columns
        listing.scroll_end(animate=False)
        await settle(app)
        assert listing.scroll_y == listing.max_scroll_y
        last = items[-1]
        assert listing.region.contains_region(last.region)
        assert app.screen.get_widget_at(last.region.x, last.region.y)[0] is last
        await listing.query(Static).remove()
        await listing.mount(Static("alone"))
        await settle(app)
        assert not listing.show_vertical_scrollbar
        assert listing.scroll_y == 0
        assert listing.query_one(Static).size.width == 20


@sync
async def test_a_box_whose_text_grows_past_it_gets_its_scroll_bar_and_scrolls_to_the_end():
    # no widget is added: the box's scrollable size grows as its text's rows do, which the
    # layout sets without asking for another layout; the scroll bar coming asks for one
    screen = SingleLayoutPanels()
    app = Host(screen)
    async with app.run_test(size=(80, 12)) as pilot:
        await pilot.pause()
        box = screen.query_one("#grows", VerticalScroll)
        inner = screen.query_one("#inner", Static)
        await settle(app)
        assert not box.show_vertical_scrollbar
        inner.update("\n".join(f"line {i}" for i in range(10)))
        await settle(app)
        assert box.virtual_size.height == 10
        assert box.show_vertical_scrollbar
        assert inner.size.width == 20 - box.vertical_scrollbar.size.width
        assert box.vertical_scrollbar.window_virtual_size == 10
        box.scroll_end(animate=False)
        await settle(app)
        assert box.scroll_y == 10 - 4
        assert app.screen.get_widget_at(box.region.x, box.region.bottom - 1)[0] is inner
        inner.update("short")
        await settle(app)
        assert not box.show_vertical_scrollbar
        assert box.scroll_y == 0
        assert inner.size.width == 20


@sync
async def test_what_a_layout_resizes_is_drawn_once_and_scroll_bars_it_left_alone_not_at_all():
    screen = SingleLayoutPanels()
    app = Host(screen)
    async with app.run_test(size=(80, 12)) as pilot:
        await pilot.pause()
        log = screen.query_one(Log)
        log.write_lines(f"line {i}" for i in range(20))
        await settle(app)
        assert log.show_vertical_scrollbar
        counted = Counted(screen)
        text = screen.query_one("#text", Static)
        counted.watch(text)
        counted.watch(log.vertical_scrollbar)
        text.update("two\nrows")
        await settle(app)
        assert text.size.height == 2
        assert counted.layouts == 1
        assert counted.drawn.get(text) == 1  # in the layout's frame, not again after it
        assert counted.drawn.get(log.vertical_scrollbar) is None  # the log did not change


class HiddenLog(Screen[None]):
    """A log hidden until it is shown, as the main screen's transition log is until a run."""

    DEFAULT_CSS = """
    Log { height: 4; width: 20; display: none; }
    """

    def __init__(self) -> None:
        super().__init__()
        use_live_compositor(self)

    def compose(self) -> ComposeResult:
        yield Static("above")
        yield Log()


class SingleLayoutHiddenLog(HiddenLog, SingleLayout):
    pass


@pytest.mark.parametrize(("screen_class", "layouts"), [(SingleLayoutHiddenLog, 1), (HiddenLog, 2)])
@sync
async def test_a_log_shown_the_first_time_lays_the_screen_out_once_with_its_scroll_bar(
    screen_class, layouts
):
    # Textual shows the log's scroll bar after the layout that placed it, and showing it asks
    # for a layout that places it again (Textual's own screen: 2)
    screen = screen_class()
    app = Host(screen)
    async with app.run_test(size=(80, 12)) as pilot:
        await pilot.pause()
        log = screen.query_one(Log)
        log.write_lines(f"line {i}" for i in range(10))
        await settle(app)
        counted = Counted(screen)
        log.display = True
        await settle(app)
        assert counted.layouts == layouts
        bar = log.vertical_scrollbar
        assert bar.display and log.show_vertical_scrollbar
        assert app.screen.get_widget_at(bar.region.x, bar.region.y)[0] is bar
        assert bar.window_virtual_size == 10
        log.display = False  # hidden and shown again: the bar is shown already
        await settle(app)
        log.display = True
        await settle(app)
        assert counted.layouts == layouts + 2
