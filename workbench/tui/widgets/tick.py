"""A checkbox that reads the same in every terminal and in ASCII mode: ``[X]`` or ``[ ]``.

Textual's checkbox draws ``▐X▌`` whether it is ticked or not (only the colour changes), which
reads as ticked on a plain or monochrome terminal.
"""

from __future__ import annotations

from textual.content import Content

from ..textual_private import DrawnCheckbox


class Tick(DrawnCheckbox):
    """``Checkbox`` drawn as ``[X]`` when ticked and ``[ ]`` when not."""

    def box(self) -> Content:
        style = self.get_visual_style("toggle--label")
        return Content.assemble(("[", style), ("X" if self.value else " ", style), ("]", style))
