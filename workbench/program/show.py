"""A loaded program as text for a person: its globals, each panel with its activities and their
values, and the links between them, in lines of at most 80 columns.

Nothing is cut without saying so: a long value (an If's condition, a Data's text) wraps onto
lines indented under its activity; a Key Press shows its key by name; a Code Activity's C#
comes as a block of its own, each line marked ``|``. A value longer than
:data:`VALUE_LINES` lines ends with a note of how much was left out. Control characters in the
file's text are shown escaped, never sent to the terminal.
"""

from __future__ import annotations

import re
import textwrap

from . import kinds as K
from .keys import KEY_NAMES
from .model import ELSE, Activity, Program

WIDTH = 80
#: where an activity's own lines (wrapped values, its outputs) start
INDENT = " " * 10
#: the most lines one value of an activity takes
VALUE_LINES = 12

_CONTROL = re.compile(r"[\x00-\x08\x0b-\x1f\x7f-\x9f]")


def count(n: int, one: str, many: str = "") -> str:
    """``1 panel``, ``0 links``, ``32 activities`` (``many`` for plurals not made with -s)."""
    return f"{n:,} {one}" if n == 1 else f"{n:,} {many or one + 's'}"


def _clean(text: str) -> str:
    return _CONTROL.sub(lambda m: f"\\x{ord(m.group()):02x}", text.expandtabs(4))


def one_line(text: str, width: int) -> str:
    """``text`` on one line of at most ``width`` columns, line breaks and control characters
    escaped, ending in ``...`` when it was cut."""
    text = _clean(text[: width * 4].replace("\n", "\\n"))
    return text if len(text) <= width else text[: width - 3] + "..."


def _wrap(first: str, text: str, indent: str = INDENT) -> list[str]:
    """``first`` + ``text`` in lines of at most WIDTH columns, the text's own line breaks kept,
    continued lines starting at ``indent``; at most VALUE_LINES lines, then a note."""
    lines: list[str] = []
    prefix = first
    # no more text than VALUE_LINES full lines can show is wrapped
    for paragraph in _clean(text[: VALUE_LINES * WIDTH + 1]).splitlines() or [""]:
        wrapped = textwrap.wrap(
            paragraph,
            WIDTH,
            initial_indent=prefix,
            subsequent_indent=indent,
            break_on_hyphens=False,
        )
        lines += wrapped or [prefix.rstrip()]
        prefix = indent
        if len(lines) > VALUE_LINES:
            break
    if len(lines) > VALUE_LINES:
        lines = lines[:VALUE_LINES]
        lines.append(
            f"{indent}... (cut: {count(len(text), 'character')}; "
            f"the first {VALUE_LINES} lines are shown)"
        )
    return lines


def _keys(values: tuple[str, ...]) -> str:
    names = []
    for text in values:
        number = text.strip()
        name = KEY_NAMES.get(int(number)) if number.isdigit() and len(number) < 6 else None
        names.append(name or f"key number {number[:10]}")
    return "+".join(names)


def _code(activity: Activity) -> list[str]:
    """A Code Activity's references, then its C# as a block of its own."""
    lines = []
    references = [v.strip() for v in activity.values[2:] if v.strip()]
    if references:
        lines += _wrap(f"{INDENT}references: ", ", ".join(references), INDENT + "  ")
    source = _clean(activity.value(1)).rstrip().splitlines()
    while source and not source[0].strip():
        source.pop(0)
    lines.append(f"{INDENT}C#, {count(len(source), 'line')}:")
    mark = INDENT + "| "
    for line in source:
        line = line.rstrip()
        while len(mark) + len(line) > WIDTH:
            cut = WIDTH - len(mark) - 1
            lines.append(mark + line[:cut] + "\\")
            line = line[cut:]
        lines.append((mark + line).rstrip())
    return lines


def _activity(program: Program, activity: Activity) -> list[str]:
    head = f"  {activity.id:>4}  {program.label(activity)}"
    kind = activity.kind
    if kind == K.KEY_PRESS:
        return _wrap(f"{head}: ", _keys(activity.values))
    if kind == K.CODE:
        name = activity.value(0).strip() or "(unnamed)"
        return [
            *_wrap(f"{head}: class ", f"{name}, run as the sensor-JSON built-in"),
            *_code(activity),
        ]
    if kind in (K.IF, K.SWITCH):
        word = "if" if kind == K.IF else "case"
        lines = [head]
        for pin, condition in enumerate(activity.values):
            lines += _wrap(f"{INDENT}out {pin} {word} ", condition, INDENT + "    ")
        return lines
    if kind == K.BLOCK:
        pairs = zip(activity.values[::2], activity.values[1::2], strict=False)
        values = ", ".join(f"{name} = {expr}" for name, expr in pairs if name.strip())
    else:
        values = " | ".join(v for v in activity.values if v)
    return _wrap(f"{head}: ", values) if values else [head]


def describe_program(program: Program) -> list[str]:
    """The lines of ``workbench viple show``."""
    lines = _wrap("", f"{program.source}:", "  ")
    lines += _wrap("", f"VIPLE {program.version}, digest {program.digest[:16]}", "  ")
    lines.append(
        f"{count(len(program.panels), 'panel')}, "
        f"{count(len(program.activities), 'activity', 'activities')}, "
        f"{count(len(program.links), 'link')}"
    )
    if program.globals:
        lines.append("globals:")
        for v in program.globals:
            lines += _wrap("  ", f"{v.name} ({v.type})", "    ")
    for panel in program.panels.values():
        lines.append("")
        inputs = ", ".join(f"{v.name} ({v.type})" for v in panel.inputs)
        lines += _wrap("", f"panel {panel.name}" + (f": inputs {inputs}" if inputs else ""), "  ")
        for aid in panel.activities:
            lines += _activity(program, program.activities[aid])
            for pin, links in sorted(program.outputs.get(aid, {}).items()):
                for link in links:
                    target = program.activities.get(link.target)
                    label = program.label(target) if target is not None else "?"
                    where = "else" if pin == ELSE else f"out {pin}"
                    into = f" (in {link.in_pin})" if link.in_pin else ""
                    lines += _wrap(
                        f"{INDENT}{where} -> ", f"{link.target} {label}{into}", INDENT + "    "
                    )
    return lines
