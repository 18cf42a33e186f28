"""What setting an exercise up again would leave behind: the work of its attempt under way.

A set-up begins a new attempt, and an objective that has not passed yet is checked against the
new attempt's work only; the runs, drive keys, VIPLE programs and maze edits of the attempt
before stop counting for it (objectives that passed stay passed, and answers are kept with the
exercise, not the attempt). The labs screen asks before it sets up an exercise that has such
work, naming it in these words.
"""

from __future__ import annotations

from dataclasses import dataclass

from workbench.control.station import LabStation

from .checks import ExerciseProgress, attempt_of
from .model import Exercise


@dataclass(frozen=True)
class AttemptWork:
    """The work of an exercise's attempt under way, and the objectives it may still count for."""

    runs: int
    keys: int
    programs: int
    edits: int
    #: the texts of the exercise's objectives that have not passed yet
    open_objectives: tuple[str, ...]

    def words(self) -> str:
        """The work, as a list: ``3 runs, 12 drive keys and 1 maze edit``."""
        parts = [
            f"{n} {what}{'' if n == 1 else 's'}"
            for n, what in (
                (self.runs, "run"),
                (self.keys, "drive key"),
                (self.programs, "VIPLE program"),
                (self.edits, "maze edit"),
            )
            if n
        ]
        return parts[0] if len(parts) == 1 else f"{', '.join(parts[:-1])} and {parts[-1]}"


def work_at_stake(
    station: LabStation, lab: str, exercise: Exercise, progress: ExerciseProgress | None
) -> AttemptWork | None:
    """The work a new set-up of ``exercise`` would stop counting (None: none would be lost,
    because it was never set up here, its attempt has no work yet, or every objective passed)."""
    attempt = attempt_of(station, lab, exercise)
    if attempt is None:
        return None
    open_objectives = tuple(
        o.text for o in (progress.objectives if progress is not None else ()) if not o.passed
    )
    if progress is not None and not open_objectives:
        return None
    mine = attempt.id
    work = AttemptWork(
        runs=sum(r.attempt == mine for r in station.runs),
        keys=sum(u.attempt == mine for u in station.key_uses),
        programs=sum(c.attempt == mine for c in station.viple),
        edits=sum(e.attempt == mine for e in station.edits),
        open_objectives=open_objectives,
    )
    if not (work.runs or work.keys or work.programs or work.edits):
        return None
    return work
