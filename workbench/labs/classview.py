"""The class as the instructor's console shows it: every student, the exercise they have open,
its objectives and who waits for sign-off, read from the store.

:func:`read_class` reads it all in one go (the console calls it about once a second, in a
thread); :func:`read_request` reads what one request rests on: the exercise's saved progress,
the objectives' evidence and the run they rest on, and the sign-off fields an instructor signs.
Nothing here imports Textual.

Everything read here reaches the instructor's terminal, and much of it was written by a
student's app (the evidence, the driver, the partner's name) or read from their files (a
maze's or program's name). So every text the console is handed is made
:func:`~workbench.files.terminal.terminal_safe` here, whatever the console does with it; the
sign-off itself is made from the progress as saved (:meth:`Request.fields`).
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, field, fields, replace
from typing import Any

from workbench.files.terminal import data_problem, terminal_safe, terminal_safe_data

from .checks import ExerciseProgress
from .model import Lab
from .partners import PairNotConfirmed, partner_problem
from .progress import signoff_driver
from .queue import QueueEntry
from .signoff_record import Evidence, RecordFields
from .store import Store


@dataclass(frozen=True)
class StudentRow:
    """One student (or pair) of the class."""

    student: str
    #: the partner of the student's last request ("" when alone or not known)
    partner: str
    lab: str
    exercise: str
    #: the exercise's title ("" when the lab files no longer have it)
    title: str
    #: each objective's text and whether it passes (empty: nothing saved yet)
    objectives: tuple[tuple[str, bool], ...]
    #: the place of the open exercise's request in the queue (None: not waiting)
    waiting: int | None
    #: the open exercise has been signed off
    signed: bool
    #: the saved progress could not be read (why)
    problem: str = ""


@dataclass(frozen=True)
class ClassView:
    rows: tuple[StudentRow, ...]
    queue: tuple[QueueEntry, ...]


def titles(labs: list[Lab]) -> dict[tuple[str, str], str]:
    return {(lab.id, ex.id): ex.title for lab in labs for ex in lab.exercises}


def read_class(store: Store, labs: list[Lab]) -> ClassView:
    """The class as the store has it now."""
    names = titles(labs)
    queue = store.signoff_queue()
    places = store.places()
    records = store.signoffs()
    signed = {(r.student, r.lab, r.exercise) for r in records}
    signed |= {(r.partner, r.lab, r.exercise) for r in records if r.partner}
    waiting = {(e.student, e.lab, e.exercise): n for n, e in enumerate(queue, 1)}
    partners = {e.student: e.partner for e in queue}
    rows = []
    for student, (lab, exercise) in sorted(places.items(), key=lambda p: p[0].casefold()):
        objectives: tuple[tuple[str, bool], ...] = ()
        problem = ""
        saved = store.progress(student, lab).get((lab, exercise))
        if saved is not None:
            try:
                progress = ExerciseProgress.from_dict(saved)
                objectives = tuple((safe(o.text), o.passed) for o in progress.objectives)
            except ValueError as exc:
                problem = str(exc)
        rows.append(
            StudentRow(
                student=safe(student),
                partner=safe(partners.get(student, "")),
                lab=safe(lab),
                exercise=safe(exercise),
                title=safe(names.get((lab, exercise), "")),
                objectives=objectives,
                waiting=waiting.get((student, lab, exercise)),
                signed=(student, lab, exercise) in signed,
                problem=safe(problem),
            )
        )
    return ClassView(tuple(rows), tuple(safe_entry(e) for e in queue))


def safe(text: str) -> str:
    """One line of text as the console may show it (see the module's notes)."""
    return terminal_safe(text)


def safe_entry(entry: QueueEntry) -> QueueEntry:
    """A request with every text it holds :func:`safe` (an id a lab file gives, or a name the
    roster holds, is as it was)."""
    texts: dict[str, Any] = {
        f.name: safe(v) for f in fields(entry) if isinstance(v := getattr(entry, f.name), str)
    }
    return replace(entry, **texts)


@dataclass(frozen=True)
class Request:
    """What one request for sign-off rests on, for the instructor to judge and sign."""

    entry: QueueEntry
    title: str
    #: the exercise's saved progress (None: nothing saved, or unreadable: see ``problem``)
    progress: ExerciseProgress | None
    #: the run the objectives rest on: its record file and figures (None: no run)
    run: dict[str, Any] | None
    problem: str = ""
    #: the progress as saved, which a sign-off records (``progress`` is it made safe to show;
    #: None: the same)
    saved: ExerciseProgress | None = field(default=None, repr=False, compare=False)
    #: why the partner the request names cannot be on the sign-off ("" when they can, or
    #: none is named; see :mod:`.partners`)
    partner_problem: str = ""

    @property
    def passed(self) -> bool:
        return self.progress is not None and self.progress.passed

    def fields(self, partner_agrees: bool | None = None) -> RecordFields:
        """The sign-off's fields: the pair of the request, the saved evidence, and as driver
        the person whose work the evidence rests on (else the request's driver).

        A request that names a partner needs the instructor's word on them: with
        ``partner_agrees`` the partner is on the sign-off (ValueError when they cannot be,
        :attr:`partner_problem`), with False it is the student's alone, and without it
        :class:`~.partners.PairNotConfirmed` is raised."""
        progress = self.saved or self.progress
        if progress is None:
            raise ValueError(f"{self.entry.pair} has no saved progress in this exercise")
        entry = self.entry
        saved = data_problem([asdict(o) for o in progress.objectives], "objectives")
        if saved:  # (what a signing error says would show it raw)
            raise ValueError(
                f"the saved progress cannot be signed: {saved}; the workbench never saves one, "
                "so decline the request and ask for the work again"
            )
        if entry.partner and partner_agrees is None:
            raise PairNotConfirmed(f"confirm that {entry.partner} worked with {entry.student}")
        if entry.partner and partner_agrees and self.partner_problem:
            raise ValueError(self.partner_problem)
        partner = entry.partner if partner_agrees else ""
        people = {name for name in (entry.student, partner) if name}
        return RecordFields(
            student=entry.student,
            lab=entry.lab,
            exercise=entry.exercise,
            driver=signoff_driver(progress, people) or entry.driver or entry.student,
            partner=partner,
            evidence=Evidence.of_progress(progress),
            objectives_passed=progress.passed,
        )


def evidence_run(progress: ExerciseProgress) -> dict[str, Any] | None:
    """The evidence of the first passing objective that rests on a run (its number, driver,
    maze, figures and record), else None."""
    for o in progress.objectives:
        if o.passed and isinstance(o.evidence, dict) and "metrics" in o.evidence:
            return dict(o.evidence)
    return None


def read_request(store: Store, entry: QueueEntry, labs: list[Lab]) -> Request:
    """The saved progress of ``entry``'s exercise and the run its objectives rest on."""
    title = safe(titles(labs).get((entry.lab, entry.exercise), entry.exercise))
    shown = safe_entry(entry)
    pairing = safe(partner_problem(entry.student, entry.partner, store.places()))
    saved = store.progress(entry.student, entry.lab).get((entry.lab, entry.exercise))
    if saved is None:
        return Request(
            shown, title, None, None, "nothing saved for this exercise yet", partner_problem=pairing
        )
    try:
        progress = ExerciseProgress.from_dict(saved)
        safe_progress = ExerciseProgress.from_dict(terminal_safe_data(saved))
    except ValueError as exc:
        return Request(shown, title, None, None, safe(str(exc)), partner_problem=pairing)
    return Request(
        shown,
        title,
        safe_progress,
        evidence_run(safe_progress),
        saved=progress,
        partner_problem=pairing,
    )
