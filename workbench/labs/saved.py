"""A pair's saved lab progress as one read of the store: what the labs screen shows when it
opens, read in a thread of its own (a course database may take up to its deadline to answer,
or not answer at all)."""

from __future__ import annotations

from dataclasses import dataclass, field

from .checks import MAX_ANSWER, ExerciseProgress
from .store import Store, StoreUnavailable

Key = tuple[str, str]


@dataclass
class SavedProgress:
    """What the store holds for a student (and partner), ready to show."""

    progress: dict[Key, ExerciseProgress] = field(default_factory=dict)
    #: (lab, exercise) -> (instructor, signed at) of its last sign-off
    signed: dict[Key, tuple[str, str]] = field(default_factory=dict)
    drivers: dict[Key, str] = field(default_factory=dict)
    #: the exercise the student had open last
    place: Key | None = None
    #: the database could not be reached: nothing was read
    unreachable: bool = False
    #: what the student is told about what was read ("" when all is well)
    problem: str = ""


def read_saved(store: Store, student: str, partner: str = "") -> SavedProgress:
    """Everything the labs screen shows of what was saved; never raises (a damaged database
    must not stop the lab: the problem is said instead)."""
    try:
        rows = store.progress(student)
        signoffs = store.signoffs(student=student)
        drivers = store.drivers(student, partner)
    except StoreUnavailable:
        return SavedProgress(unreachable=True)
    except Exception as exc:
        return SavedProgress(problem=f"cannot read saved progress: {exc}")
    saved = SavedProgress(drivers=drivers)
    damaged, cut = [], []
    for key, data in rows.items():
        try:
            progress = ExerciseProgress.from_dict(data)
        except ValueError:
            damaged.append("/".join(key))
            continue
        cut += [f"{'/'.join(key)} {question}" for question in progress.cut]
        saved.progress[key] = progress
    if damaged:
        saved.problem = f"saved progress unreadable (starts afresh): {', '.join(damaged)}"
    elif cut:
        saved.problem = (
            f"saved answers longer than {MAX_ANSWER} characters were cut to their first "
            f"{MAX_ANSWER}: {', '.join(cut[:3])}{' ...' if len(cut) > 3 else ''}"
        )
    saved.signed = {(row.lab, row.exercise): (row.instructor, row.signed_at) for row in signoffs}
    try:
        saved.place = store.place(student)
    except Exception:  # where the student was is a convenience, never a reason to fail
        saved.place = None
    return saved
