"""A compositor for live screens: a partial update renders only the widgets its changes show.

Textual's compositor renders a partial update (some changed spans of some lines) by cropping
the screen to the box around *all* the changed regions and asking every widget whose parent's
area overlaps that box for *all* its lines. On the main screen, where the maze view changes a
few cells every tick and the run status and sensor panels a line each a few times a second,
that means eight to a dozen widgets rendering every one of their lines for each frame: most of
the app's CPU while the robot drives.

:class:`LiveCompositor` renders the same update with less work, and with the same result on the
terminal:

  * the changed regions are grouped by the front-most widget that holds each of them, and each
    group is rendered on its own (a cell changed in the maze and a line changed in the side panel
    are no longer one box covering most of the screen); groups whose boxes overlap are rendered
    as one, so that no widget is rendered twice for one update;
  * a widget is asked only for the lines of the group's box, and only if what it shows on the
    screen overlaps that box;
  * once a widget that covers the whole box has been rendered, the widgets behind it are not
    (the compositor paints front to back and the first widget to paint a cell wins, so they
    could not show there anyway).

Everything else (layout, full updates, the cursor, mouse lookups) is Textual's own. The screen
the compositor serves is the only one that uses it; ``tests/app/test_live_compositor.py``
checks, frame by frame, that its partial updates leave the screen exactly as a full render does.
"""

from __future__ import annotations

from collections.abc import Iterable
from typing import Any

from rich.console import Console, ConsoleOptions, RenderResult
from textual._compositor import ChopsUpdate, Compositor, CompositorUpdate
from textual.geometry import Region
from textual.screen import Screen
from textual.strip import Strip
from textual.widget import Widget


class GroupedUpdate(CompositorUpdate):
    """Several partial updates written one after the other."""

    def __init__(self, updates: list[ChopsUpdate]) -> None:
        self.updates = updates

    def __rich_console__(self, console: Console, options: ConsoleOptions) -> RenderResult:
        for update in self.updates:
            yield from update.__rich_console__(console, options)

    def render_segments(self, console: Console) -> str:
        return "".join(update.render_segments(console) for update in self.updates)


class LiveCompositor(Compositor):
    """Textual's compositor with cheaper partial updates (see the module's description)."""

    # (a GroupedUpdate is a CompositorUpdate, all Textual needs of it; its annotation is narrower)
    def render_partial_update(self) -> ChopsUpdate | GroupedUpdate | None:  # type: ignore[override]
        screen = self.size.region
        regions = [r for r in (d.intersection(screen) for d in self._dirty_regions) if r]
        self._dirty_regions.clear()
        if not regions:
            return None
        groups: dict[Widget | None, list[Region]] = {}
        visible = [(widget, region.intersection(clip)) for widget, (region, clip) in
                   self.visible_widgets.items()]  # fmt: skip
        for changed in regions:
            owner = None
            for widget, shown in visible:  # front to back
                if shown.overlaps(changed):
                    if shown.contains_region(changed):
                        owner = widget
                    break
            groups.setdefault(owner, []).append(changed)
        chop_ends = [cut_set[1:] for cut_set in self.cuts]
        updates = []
        for crop, group in merged_crops(groups.values()):
            spans = list(self._regions_to_spans(group))
            rendered = {y for y, _, _ in spans}.__contains__
            chops = self._render_chops(crop, rendered)
            updates.append(ChopsUpdate(chops, spans, chop_ends))
        return updates[0] if len(updates) == 1 else GroupedUpdate(updates)

    def _get_renders(
        self, crop: Region | None = None
    ) -> Iterable[tuple[Region, Region, list[Strip]]]:
        if crop is None:
            yield from super()._get_renders(crop)
            return
        crop_x, crop_y, crop_width, crop_height = crop
        crop_right = crop_x + crop_width
        crop_bottom = crop_y + crop_height
        for widget, (region, clip) in self.visible_widgets.items():  # front to back
            x, y, width, height = region.intersection(clip)
            top = max(y, crop_y)
            bottom = min(y + height, crop_bottom)
            if top >= bottom or x >= crop_right or x + width <= crop_x:
                continue
            # only the crop's lines, all the columns the widget shows: the strips are the ones
            # Textual would cut from a whole render
            band = Region(x, top, width, bottom - top)
            yield (
                region,
                band,
                widget.render_lines(Region(x - region.x, top - region.y, width, bottom - top)),
            )
            if (
                x <= crop_x
                and crop_right <= x + width
                and y <= crop_y
                and crop_bottom <= y + height
            ):
                return  # the crop is all this widget's: nothing behind it shows there


def merged_crops(groups: Iterable[list[Region]]) -> list[tuple[Region, list[Region]]]:
    """Each group's crop (the box around its regions), with groups whose crops overlap made one.

    A widget is rendered for every crop it shows in: a scroll bar's own change and the change of
    the log it scrolls (whose box holds the bar's column), or a panel's and the lines inside it,
    would render the widgets they share twice. The box around both holds the same widgets.
    """
    pending = [(Region.from_union(group), group) for group in groups]
    merged: list[tuple[Region, list[Region]]] = []
    while pending:
        crop, group = pending.pop()
        for i, (other, regions) in enumerate(merged):
            if other.overlaps(crop):
                del merged[i]
                pending.append((other.union(crop), regions + group))
                break
        else:
            merged.append((crop, group))
    return merged


def use_live_compositor(screen: Screen[Any]) -> None:
    """Have ``screen`` (not yet shown) drawn by a :class:`LiveCompositor`."""
    screen._compositor = LiveCompositor()
