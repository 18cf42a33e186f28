"""The one shape of a problem found in what a user gave the workbench (a maze, an FSM, a lab, a
users file, a VIPLE program), and the one error of an expression (an FSM's guards and
actions, a VIPLE program's Calculate, If, While ...).

A :class:`Problem` says what is wrong, how to fix it and where, with as much of the place as
is known: the file, its line and column, the keys leading to it inside a definition, the
panel and activity of a VIPLE program. Each reader fills the parts it knows; the text is
``WHERE: message (hint)`` with the parts that do not apply left out.
"""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class Problem:
    """One thing wrong, with how to fix it and where.

    ``line`` and ``column`` count from 1 (0: not known, or the whole file); in a definition
    read from a file (an FSM's), ``column`` may be the column inside the value at ``path``.
    """

    message: str
    hint: str = ""
    #: the file (or text) it is in, as the user named it
    source: str = ""
    line: int = 0
    column: int = 0
    #: the keys leading to it inside a definition, e.g. ("states", "Forward", "to")
    path: tuple[str | int, ...] = ()
    #: the panel of a VIPLE program, and the activity there (its id, kind number and label)
    panel: str | None = None
    activity: int | None = None
    kind: int | None = None
    what: str = ""
    #: the word before the hint in the text ("hint": ``(hint: fix)``; none: ``(fix)``)
    hint_word: str = ""

    def where(self) -> str:
        """The place as the text gives it: ``file:line:column``, the path of keys
        (``states.Forward.to``), ``panel NAME``, ``activity ID (kind K, what)``."""
        parts = []
        place = self.source
        if self.line:
            place += f":{self.line}"
            if self.column:
                place += f":{self.column}"
        if place:
            parts.append(place)
        if self.path:
            keys = ""
            for part in self.path:
                if isinstance(part, int):
                    keys += f"[{part}]"
                else:
                    keys += f".{part}" if keys else str(part)
            parts.append(keys)
        if self.panel is not None:
            parts.append(f"panel {self.panel}")
        if self.activity is not None:
            label = f"activity {self.activity}"
            if self.kind is not None:
                label += f" (kind {self.kind}" + (f", {self.what})" if self.what else ")")
            parts.append(label)
        return ": ".join(parts)

    def __str__(self) -> str:
        text = f"{self.where()}: {self.message}"
        if not self.hint:
            return text
        return text + (f" ({self.hint_word}: {self.hint})" if self.hint_word else f" ({self.hint})")


class ExprError(ValueError):
    """An expression that cannot be compiled or evaluated.

    ``column`` counts from 1 in the expression's ``text``. With the text, the message names
    it: ``message in 'text' at column C (hint)`` (an FSM's expressions); without it, the
    column leads: ``column C: message (hint)`` (a VIPLE program's, whose activity the
    program's problem names).
    """

    #: an expression shown in a message is cut to this many characters
    SHOWN = 60

    def __init__(
        self, message: str, column: int | None = None, hint: str = "", text: str = ""
    ) -> None:
        self.message = message
        self.column = column
        self.hint = hint
        self.text = text
        super().__init__(str(self))

    def __str__(self) -> str:
        hint = f" ({self.hint})" if self.hint else ""
        if self.text:
            shown = self.text
            if len(shown) > self.SHOWN:
                shown = shown[: self.SHOWN - 3] + "..."
            where = f" in {shown!r}"
            if self.column is not None:
                where += f" at column {self.column}"
            return f"{self.message}{where}{hint}"
        lead = f"column {self.column}: " if self.column is not None else ""
        return f"{lead}{self.message}{hint}"
