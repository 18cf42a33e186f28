"""A loaded program as text for a person: its globals, each panel with its activities and their
values, and the links between them, in lines that fit 80 columns."""

from __future__ import annotations

from .model import ELSE, Program

WIDTH = 80


def _fit(text: str, width: int = WIDTH) -> str:
    return text if len(text) <= width else text[: width - 3] + "..."


def describe_program(program: Program) -> list[str]:
    """The lines of ``workbench viple show``."""
    lines = [
        _fit(f"{program.source}: VIPLE {program.version}, digest {program.digest[:16]}"),
        _fit(
            f"{len(program.panels)} panels, {len(program.activities)} activities, "
            f"{len(program.links)} links"
        ),
    ]
    if program.globals:
        lines.append("globals:")
        lines += [_fit(f"  {v.name} ({v.type})") for v in program.globals]
    for panel in program.panels.values():
        lines.append("")
        inputs = ", ".join(f"{v.name} ({v.type})" for v in panel.inputs)
        lines.append(_fit(f"panel {panel.name}" + (f": inputs {inputs}" if inputs else "")))
        for aid in panel.activities:
            activity = program.activities[aid]
            values = " | ".join(v for v in activity.values if v)
            head = f"  {aid:>4}  {program.label(activity)}"
            lines.append(_fit(head + (f": {values}" if values else "")))
            for pin, links in sorted(program.outputs.get(aid, {}).items()):
                for link in links:
                    target = program.activities.get(link.target)
                    label = program.label(target) if target is not None else "?"
                    where = "else" if pin == ELSE else f"out {pin}"
                    into = f" (in {link.in_pin})" if link.in_pin else ""
                    lines.append(_fit(f"          {where} -> {link.target} {label}{into}"))
    return lines
