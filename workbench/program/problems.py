"""Problems found in a VIPLE program, each naming the file, panel and activity it is about."""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class Problem:
    """One thing wrong with a program; the fields say where and how to fix it.

    Shown as ``FILE: panel NAME: activity ID (kind K, what): message (hint)``; the parts
    that do not apply (a problem with the whole file) are left out.
    """

    source: str
    message: str
    hint: str = ""
    panel: str | None = None
    activity: int | None = None
    kind: int | None = None
    what: str = ""

    def __str__(self) -> str:
        parts = [self.source]
        if self.panel is not None:
            parts.append(f"panel {self.panel}")
        if self.activity is not None:
            label = f"activity {self.activity}"
            if self.kind is not None:
                label += f" (kind {self.kind}" + (f", {self.what})" if self.what else ")")
            parts.append(label)
        text = ": ".join(parts) + f": {self.message}"
        return text + (f" ({self.hint})" if self.hint else "")


class ProgramError(ValueError):
    """A program that cannot be loaded or run, with every problem found."""

    def __init__(self, problems: list[Problem]) -> None:
        self.problems = list(problems)
        super().__init__("\n".join(str(p) for p in self.problems))
