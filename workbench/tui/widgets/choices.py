"""A multiple-choice question's answer: its choices, one under the other, one of them picked.

Each choice is shown whole (a long one wraps) with ``(*)`` before the one picked and ``( )``
before the others, the same in every terminal and in ASCII mode. Up and down move between the
choices, enter or space picks one, and a click picks the choice clicked. The answer is the
choice's text, as the lab file spells it.
"""

from __future__ import annotations

import textwrap

from textual.app import ComposeResult
from textual.content import Content
from textual.geometry import Size
from textual.widgets import RadioSet

from workbench.labs.model import normalise_choice

from ..textual_private import DrawnRadioButton

#: the cells before a choice's text: its box and a space
INDENT = 4


class Choice(DrawnRadioButton):
    """One choice: ``(*)`` when it is the one picked, ``( )`` when not; a long one wraps, its
    lines under the first one's text."""

    DEFAULT_CSS = """
    Choice {
        height: auto;
    }
    """

    def __init__(self, text: str, value: bool = False) -> None:
        super().__init__(Content(text), value=value)
        self.text = text

    def box(self) -> Content:
        style = self.get_visual_style("toggle--label")
        return Content.assemble(("(", style), ("*" if self.value else " ", style), (")", style))

    def lines(self, width: int) -> list[str]:
        """The choice's text in lines that fit ``width`` cells beside the box."""
        return textwrap.wrap(self.text, max(1, width - INDENT - 1)) or [""]

    def render(self) -> Content:
        style = self.get_visual_style("toggle--label")
        lines = self.lines(self.content_region.width)
        label = Content("\n".join([lines[0], *(" " * INDENT + line for line in lines[1:])]))
        return Content.assemble(self.box(), " ", label.stylize_before(style))

    def get_content_height(self, container: Size, viewport: Size, width: int) -> int:
        return len(self.lines(width))


class Choices(RadioSet):
    """The choices of one question (``labels``: as shown, in the same order as ``choices``),
    with ``answer`` picked when it is one of them."""

    def __init__(
        self, choices: tuple[str, ...], labels: list[str], answer: str = "", *, id: str
    ) -> None:
        super().__init__(id=id)
        self.choices = choices
        self.labels = labels
        picked = normalise_choice(answer) if answer.strip() else None
        self.picked_at_start = next(
            (i for i, choice in enumerate(choices) if normalise_choice(choice) == picked), None
        )

    def compose(self) -> ComposeResult:
        for index, label in enumerate(self.labels):
            yield Choice(label, value=index == self.picked_at_start)

    @property
    def answer(self) -> str:
        """The choice picked ("" while none is)."""
        index = self.pressed_index
        return self.choices[index] if 0 <= index < len(self.choices) else ""
