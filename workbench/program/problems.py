"""Problems found in a VIPLE program, each naming the file, panel and activity it is about."""

from __future__ import annotations

from workbench.files.problems import Problem


def program_problem(
    source: str,
    message: str,
    hint: str = "",
    panel: str | None = None,
    activity: int | None = None,
    kind: int | None = None,
    what: str = "",
) -> Problem:
    """One thing wrong with a program, shown as ``FILE: panel NAME: activity ID (kind K,
    what): message (hint)``; the parts that do not apply (a problem with the whole file) are
    left out."""
    return Problem(message, hint, source, panel=panel, activity=activity, kind=kind, what=what)


class ProgramError(ValueError):
    """A program that cannot be loaded or run, with every problem found."""

    def __init__(self, problems: list[Problem]) -> None:
        self.problems = list(problems)
        super().__init__("\n".join(str(p) for p in self.problems))
