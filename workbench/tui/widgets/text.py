"""Shared wording of the side panel: numbers in the profile's unit, ASCII or Unicode marks."""

from __future__ import annotations

from textual.widget import Widget

from workbench.sim.sensor_kinds import sensor_kind
from workbench.sim.sensors import SensorSpec


def degrees(value: float, unicode: bool) -> str:
    return f"{value:.0f}°" if unicode else f"{value:.0f} deg"


def arrow(unicode: bool) -> str:
    return "→" if unicode else "->"


def separator(unicode: bool) -> str:
    return " · " if unicode else " | "


def count(n: int, one: str, many: str = "") -> str:
    """``n`` things in words: "1 turn", "3 turns", "2 touches" (``many`` for odd plurals)."""
    return f"{n} {one}" if n == 1 else f"{n} {many or one + 's'}"


def number(value: float | int | None, unit: str = "") -> str:
    """A reading or a length: whole pixels, two decimals for metre-like units."""
    if value is None:
        return "-"
    if isinstance(value, bool):
        return "true" if value else "false"
    if unit == "px":
        return f"{value:.0f}"
    if isinstance(value, int):
        return str(value)
    return f"{value:.2f}"


def reading(spec: SensorSpec, value: float | int | None, unit: str, no_echo: float) -> str:
    """What a sensor reads, as a student would say it (in the form its kind's
    :class:`~workbench.sim.sensor_kinds.PanelForm` gives)."""
    if value is None:
        return "-"
    form = sensor_kind(spec.kind).panel
    state = form.state(value)
    if state is not None:
        return state
    shown = number(value, unit if form.unit == "length" else "")
    if form.echo and value >= no_echo:
        return f"no echo ({shown})"
    return shown


def speed(value: float | None) -> str:
    return "max" if value is None else f"{value:g}x"


def named_title(widget: Widget, word: str, name: str) -> str:
    """A panel's border title ``word name`` ("Algorithm right-wall"), or the name alone where
    the panel is too narrow for both: the name is never the part cut."""
    title = f"{word} {name}"
    room = widget.size.width - 2  # the border's corners
    return name if 0 < room < len(title) else title


def set_border_title(widget: Widget, title: str) -> None:
    """Set a panel's border title; setting it at all repaints the whole panel, so only on change."""
    if widget.border_title != title:
        widget.border_title = title
