"""Text that reaches a terminal: names, labels and evidence must never carry the control
characters a terminal acts on instead of showing.

An escape character (ESC, U+001B) starts a sequence that can set the window's title, write
the clipboard (OSC 52) or move the cursor; the other C0 controls, DEL and the C1 controls
(U+0080..U+009F, where U+009B is a CSI and U+009D an OSC on some terminals) act too. Neither
Textual nor Rich removes ESC when it draws text, so the workbench does, in two ways:

* :func:`terminal_problem`: names in the files a person gives the workbench (mazes, FSM and
  lab files, VIPLE programs) are refused at load when they hold one, with the place;
* :func:`terminal_safe`: text from anywhere else (saved evidence, run records, a store)
  is shown with each such character written as an escape (``\\x1b``) wherever it is printed.

The bidirectional controls of :mod:`.bidi` are shown escaped too: they do not act on the
terminal, but they change the order in which it shows the rest.
"""

from __future__ import annotations

import re
from collections.abc import Mapping
from typing import Any

from .bidi import BIDI_CONTROLS

#: the C0 controls, DEL and the C1 controls (Unicode's category Cc)
CONTROLS = re.compile("[\x00-\x1f\x7f-\x9f]")
#: the same, less tab and newline, for text that may run over several lines
CONTROLS_MULTILINE = re.compile("[\x00-\x08\x0b-\x1f\x7f-\x9f]")
_SHOWN = re.compile(f"{CONTROLS.pattern[:-1]}{BIDI_CONTROLS.pattern[1:-1]}]")
_SHOWN_MULTILINE = re.compile(f"{CONTROLS_MULTILINE.pattern[:-1]}{BIDI_CONTROLS.pattern[1:-1]}]")

#: how a refusal says to fix the text
FIX = "remove it: in YAML it may be written as an escape such as \\e or \\x1b inside quotes"


def _escaped(found: re.Match[str]) -> str:
    code = ord(found.group())
    return f"\\x{code:02x}" if code < 0x100 else f"\\u{code:04x}"


def terminal_safe(text: str, multiline: bool = False) -> str:
    """``text`` as it may be printed to a terminal: every control character (and bidi
    control) written as an escape, ``\\x1b`` for ESC; tab and newline are kept when
    ``multiline``."""
    pattern = _SHOWN_MULTILINE if multiline else _SHOWN
    return pattern.sub(_escaped, text)


def terminal_safe_data(value: Any) -> Any:
    """``value`` (saved evidence: mappings, lists and plain values) with every text in it,
    keys too, made :func:`terminal_safe`; anything else is kept as it is."""
    if isinstance(value, str):
        return terminal_safe(value, multiline=True)
    if isinstance(value, Mapping):
        return {terminal_safe_data(k): terminal_safe_data(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return type(value)(terminal_safe_data(v) for v in value)
    return value


def terminal_problem(text: str, what: str, multiline: bool = False) -> str:
    """Why ``text`` cannot be a name (naming the first control character and its position),
    or ``""`` when it holds none; ``what`` names the text (e.g. "the maze's name"). Tab and
    newline pass when ``multiline``."""
    found = (CONTROLS_MULTILINE if multiline else CONTROLS).search(text)
    if found is None:
        return ""
    code = ord(found.group())
    name = _NAMES.get(code, "a control character")
    return (
        f"{what} holds {name} (U+{code:04X} at position {found.start() + 1}), which a "
        "terminal would act on instead of showing"
    )


def data_problem(value: Any, where: str = "") -> str:
    """The first text in ``value`` (mappings, lists and plain values read from JSON), key or
    value, that holds a control character other than tab and newline, as
    :func:`terminal_problem` words it with its place (``maze.name``); ``""`` when none."""
    if isinstance(value, str):
        return terminal_problem(value, where or "a text", multiline=True)
    if isinstance(value, Mapping):
        for key, item in value.items():
            place = f"{where}.{key}" if where else str(key)
            problem = data_problem(str(key), f"a key of {where or 'the line'}") or data_problem(
                item, place
            )
            if problem:
                return problem
    elif isinstance(value, list | tuple):
        for index, item in enumerate(value):
            if problem := data_problem(item, f"{where}[{index}]"):
                return problem
    return ""


_NAMES = {
    0x1B: "an escape character (ESC)",
    0x07: "a bell (BEL)",
    0x9B: "a control sequence introducer (CSI)",
    0x9D: "an operating system command (OSC)",
    0x7F: "a delete character (DEL)",
}


class TerminalSafeWriter:
    """A text stream that writes everything given to it :func:`terminal_safe` (lines, CR LF
    line endings and tabs kept) to ``stream``: the command line's standard output, so no
    name, label or evidence it prints can act on the terminal. Everything else is the
    stream's own."""

    def __init__(self, stream: Any) -> None:
        self.stream = stream

    def write(self, text: str) -> int:
        # a line ending of CR LF (a CSV a command prints) is a line ending, not a control
        parts = text.split("\r\n")
        self.stream.write("\r\n".join(terminal_safe(p, multiline=True) for p in parts))
        return len(text)

    def writelines(self, lines: Any) -> None:
        for line in lines:
            self.write(line)

    def __getattr__(self, name: str) -> Any:
        return getattr(self.stream, name)
