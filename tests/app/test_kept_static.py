"""The kept static (the algorithm panel's row of states): a content it drew before is drawn from
the lines it kept, exactly as Textual's ``Static`` draws it, whatever changed in between."""

from __future__ import annotations

from textual.app import App, ComposeResult
from textual.content import Content
from textual.geometry import Region
from textual.strip import Strip
from textual.widget import Widget

from tests.app.support import sync
from workbench.tui.widgets.kept_static import KeptStatic

NAMES = ("Forward", "BesideOpening", "TurningRight", "TurnedRight", "TurningLeft")


class Host(App[None]):
    CSS = """
    KeptStatic { width: 24; height: auto; }
    .other KeptStatic { background: darkred; color: yellow; }
    """

    def compose(self) -> ComposeResult:
        yield KeptStatic(id="states")


def states(current: str) -> Content:
    """The row of states as the algorithm panel makes it, ``current`` highlighted."""
    return Content("").join(
        Content.styled(f" {name} ", "bold reverse") if name == current else Content(f" {name} ")
        for name in NAMES
    )


def textuals_lines(widget: Widget, crop: Region) -> list[Strip]:
    """The lines Textual's ``Static`` draws of the same content now, nothing kept."""
    widget._styles_cache.clear()
    widget.refresh()
    return Widget.render_lines(widget, crop)


def highlighted(lines: list[Strip]) -> list[str]:
    """The text drawn in reverse video."""
    return [
        text.strip()
        for line in lines
        for text, style, _ in line
        if style is not None and style.reverse and text.strip()
    ]


@sync
async def test_a_content_shown_again_is_drawn_as_textual_draws_it():
    app = Host()
    async with app.run_test(size=(40, 10)) as pilot:
        widget = app.query_one(KeptStatic)
        for step in ("first", "again", "other colours", "again", "padded"):
            if step == "other colours":
                app.screen.add_class("other")
            elif step == "padded":
                widget.styles.padding = (0, 1)
            for current in NAMES:
                widget.update(states(current))
                await pilot.pause()
                width, height = widget.outer_size
                assert height >= 2  # the row wraps at this width
                for crop in (Region(0, 0, width, height), Region(0, 1, width, 1),
                             Region(3, 0, 10, height)):  # fmt: skip
                    drawn = widget.render_lines(crop)
                    assert drawn == textuals_lines(widget, crop), (step, current, crop)
                assert highlighted(widget.render_lines(Region(0, 0, width, height))) == [current]
