"""Hints for the instructor: two students whose evidence rests on the same program file.

A program's content digest (the sha256 of its bytes, kept in a run's evidence as
``program_sha256``) is the same for two students only when they ran the same file. That is a
hint, not proof (a pair at one station shares its work, and is left out), so the console shows
it and the instructor judges. The files the workbench ships (example programs, starters,
built-in algorithms) are everyone's, and never a hint.
"""

from __future__ import annotations

import functools
from collections.abc import Iterable, Mapping
from dataclasses import dataclass
from pathlib import Path

from workbench.fsm.algorithms import ALGORITHM_DIR
from workbench.sim.record import file_sha256

from .checks import ATTEMPT, ExerciseProgress
from .evidence_text import program_of
from .model import LABS_DIR

#: the folders whose files ship with the workbench, and the names of the files they hold
BUNDLED_FILES = (
    (LABS_DIR.parent / "programs", "*.viple"),
    (LABS_DIR / "starters", "*"),
    (ALGORITHM_DIR, "*.yaml"),
)


@functools.cache
def bundled_digests() -> frozenset[str]:
    """The sha256 (hex) of every program, starter and algorithm file the workbench ships."""
    digests = set()
    for folder, pattern in BUNDLED_FILES:
        for path in sorted(Path(folder).glob(pattern)):
            if path.is_file():
                digests.add(file_sha256(path))
    return frozenset(digests)


@dataclass(frozen=True)
class ProgramUse:
    """One student's exercise whose passed evidence rests on a program."""

    student: str
    lab: str
    exercise: str
    digest: str
    name: str
    #: the attempt the work was done in (a pair at one station shares it)
    attempt: str = ""


@dataclass(frozen=True)
class CopyHint:
    """A program file that is the evidence of more than one student."""

    digest: str
    name: str
    uses: tuple[ProgramUse, ...]

    @property
    def students(self) -> tuple[str, ...]:
        return tuple(sorted({u.student for u in self.uses}, key=str.casefold))


def program_uses(
    student: str, progress: ExerciseProgress, bundled: frozenset[str] = frozenset()
) -> list[ProgramUse]:
    """The programs the passed objectives of one student's exercise rest on (not bundled)."""
    uses: dict[str, ProgramUse] = {}
    for state in progress.objectives:
        if not state.passed or not isinstance(state.evidence, Mapping):
            continue
        program = program_of(state.evidence)
        if program is None or program[0] in bundled:
            continue
        digest, name = program
        attempt = str(state.evidence.get(ATTEMPT) or "")
        uses.setdefault(
            digest, ProgramUse(student, progress.lab, progress.exercise, digest, name, attempt)
        )
    return list(uses.values())


def copy_hints(
    uses: Iterable[ProgramUse], pairs: Iterable[tuple[str, str]] = ()
) -> tuple[CopyHint, ...]:
    """Each program whose digest is in the evidence of two students or more who did not work
    together: not partners (``pairs``) and not in one attempt at one station."""
    together = {frozenset(p) for p in pairs if p[0] and p[1]}
    by_digest: dict[str, list[ProgramUse]] = {}
    for use in uses:
        by_digest.setdefault(use.digest, []).append(use)
    hints = []
    for digest, found in sorted(by_digest.items()):
        apart = [
            u
            for u in found
            if any(
                v.student != u.student
                and frozenset((u.student, v.student)) not in together
                and not (u.attempt and u.attempt == v.attempt)
                for v in found
            )
        ]
        if apart:
            apart.sort(key=lambda u: (u.student.casefold(), u.lab, u.exercise))
            hints.append(CopyHint(digest, apart[0].name, tuple(apart)))
    return tuple(hints)


def hints_for(student: str, hints: Iterable[CopyHint]) -> list[tuple[CopyHint, tuple[str, ...]]]:
    """The hints that name ``student``, each with the other students it names."""
    out = []
    for hint in hints:
        if student in hint.students:
            others = tuple(s for s in hint.students if s != student)
            out.append((hint, others))
    return out
