"""The class as the instructor's console shows it: every student, the exercise they have open,
its objectives and who waits for sign-off; every student's standing in every exercise (the
grid); and the programs two students' evidence share (the copy hints), read from the store.

:func:`read_class` reads it all in one go (the console calls it in a thread, at word of a
change to the store: ``labs/store/changes.py``); :func:`read_request` reads what one request
rests on: the exercise's saved progress, the objectives' evidence and the run they rest on,
and the sign-off fields an instructor signs. Nothing here imports Textual.

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
from .copy_hints import CopyHint, ProgramUse, bundled_digests, copy_hints, program_uses
from .evidence_text import programs_of
from .model import Lab
from .partners import PairNotConfirmed, partner_problem
from .progress import signoff_driver
from .signoff.signoff_record import Evidence, RecordFields
from .store.queue import QueueEntry
from .store.store import Store


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
    #: the programs (sha256 to name) the open exercise's passed objectives rest on, when
    #: more than one: its evidence mixes programs
    mixed: tuple[tuple[str, str], ...] = ()
    #: the other students whose evidence has a program of this student's (copy hints)
    same_program_as: tuple[str, ...] = ()


#: where a student stands in one exercise (a cell of the grid)
NOTHING, STARTED, PASSED, ASKED, SIGNED = "nothing", "started", "passed", "asked", "signed"


@dataclass(frozen=True)
class Standing:
    """One student in one exercise: how far, and whether asked for or given a sign-off."""

    state: str
    #: objectives passed, of how many (0 of 0: nothing saved)
    passed: int = 0
    of: int = 0
    #: questions that used up their tries and wait for the instructor
    waiting_questions: tuple[str, ...] = ()


@dataclass(frozen=True)
class ClassGrid:
    """Every student (rows) in every exercise of the labs (columns, lab by lab)."""

    students: tuple[str, ...]
    #: (lab, exercise) in the labs' order
    exercises: tuple[tuple[str, str], ...]
    #: (student, lab, exercise) to where they stand; absent: nothing saved, not asked
    cells: dict[tuple[str, str, str], Standing]

    def standing(self, student: str, lab: str, exercise: str) -> Standing:
        return self.cells.get((student, lab, exercise), Standing(NOTHING))

    def labs(self) -> tuple[str, ...]:
        return tuple(dict.fromkeys(lab for lab, _ in self.exercises))


@dataclass(frozen=True)
class ClassView:
    rows: tuple[StudentRow, ...]
    queue: tuple[QueueEntry, ...]
    grid: ClassGrid = ClassGrid((), (), {})
    #: programs that are the evidence of two students or more who did not work together
    hints: tuple[CopyHint, ...] = ()


def titles(labs: list[Lab]) -> dict[tuple[str, str], str]:
    return {(lab.id, ex.id): ex.title for lab in labs for ex in lab.exercises}


def profiles(labs: list[Lab]) -> dict[tuple[str, str], str]:
    """Each exercise's profile (the unit its evidence is measured in)."""
    return {(lab.id, ex.id): ex.setup.profile for lab in labs for ex in lab.exercises}


def _waiting_questions(progress: ExerciseProgress) -> tuple[str, ...]:
    for state in progress.objectives:
        evidence = state.evidence if isinstance(state.evidence, dict) else {}
        if state.kind == "questions" and isinstance(evidence.get("waiting"), list):
            return tuple(str(q) for q in evidence["waiting"])
    return ()


def _standing(progress: ExerciseProgress | None, asked: bool, signed: bool) -> Standing:
    passed = sum(o.passed for o in progress.objectives) if progress else 0
    of = len(progress.objectives) if progress else 0
    waiting = _waiting_questions(progress) if progress else ()
    if signed:
        state = SIGNED
    elif asked:
        state = ASKED
    elif progress is not None and progress.objectives and progress.passed:
        state = PASSED
    elif progress is not None:
        state = STARTED
    else:
        state = NOTHING
    return Standing(state, passed, of, waiting)


def read_class(store: Store, labs: list[Lab]) -> ClassView:
    """The class as the store has it now."""
    names = titles(labs)
    queue = store.queue.waiting()
    places = store.progress.places()
    records = store.signoffs.of()
    signed = {(r.student, r.lab, r.exercise) for r in records}
    signed |= {(r.partner, r.lab, r.exercise) for r in records if r.partner}
    waiting = {(e.student, e.lab, e.exercise): n for n, e in enumerate(queue, 1)}
    waiting |= {(e.partner, e.lab, e.exercise): n for n, e in enumerate(queue, 1) if e.partner}
    partners = {e.student: e.partner for e in queue}
    pairs = [(e.student, e.partner) for e in queue] + [(r.student, r.partner) for r in records]
    students = sorted(
        set(places) | {person for s, p in pairs for person in (s, p) if person}, key=str.casefold
    )
    bundled = bundled_digests()
    saved: dict[tuple[str, str, str], ExerciseProgress] = {}
    problems: dict[tuple[str, str, str], str] = {}
    uses: list[ProgramUse] = []
    for student in students:
        for (lab, exercise), data in store.progress.of(student).items():
            try:
                progress = ExerciseProgress.from_dict(data)
            except ValueError as exc:
                problems[(student, lab, exercise)] = str(exc)
                continue
            saved[(student, lab, exercise)] = progress
            uses += program_uses(student, progress, bundled)
    hints = copy_hints(uses, pairs)
    sharing: dict[str, set[str]] = {}
    for hint in hints:
        for student in hint.students:
            sharing.setdefault(student, set()).update(set(hint.students) - {student})
    rows = []
    for student in students:
        if student not in places:
            continue
        lab, exercise = places[student]
        key = (student, lab, exercise)
        found = saved.get(key)
        objectives = tuple((safe(o.text), o.passed) for o in found.objectives) if found else ()
        mixed = {d: safe(n) for d, n in programs_of(found, bundled).items()} if found else {}
        rows.append(
            StudentRow(
                student=safe(student),
                partner=safe(partners.get(student, "")),
                lab=safe(lab),
                exercise=safe(exercise),
                title=safe(names.get((lab, exercise), "")),
                objectives=objectives,
                waiting=waiting.get(key),
                signed=key in signed,
                problem=safe(problems.get(key, "")),
                mixed=tuple(sorted(mixed.items())) if len(mixed) > 1 else (),
                same_program_as=tuple(sorted(sharing.get(student, ()), key=str.casefold)),
            )
        )
    exercises = tuple((lab.id, ex.id) for lab in labs for ex in lab.exercises)
    cells = {
        (student, lab, exercise): _standing(
            saved.get((student, lab, exercise)),
            (student, lab, exercise) in waiting,
            (student, lab, exercise) in signed,
        )
        for student in students
        for lab, exercise in exercises
    }
    grid = ClassGrid(tuple(students), exercises, cells)
    safe_hints = tuple(replace(h, name=safe(h.name)) for h in hints)
    return ClassView(tuple(rows), tuple(safe_entry(e) for e in queue), grid, safe_hints)


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
    #: the exercise's profile: the unit its lengths are in
    profile: str = ""

    @property
    def programs(self) -> dict[str, str]:
        """The programs (sha256 to name, bundled files aside) the passed objectives rest on:
        more than one, and the evidence mixes programs."""
        if self.progress is None:
            return {}
        return programs_of(self.progress, bundled_digests())

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
    key = (entry.lab, entry.exercise)
    title = safe(titles(labs).get(key, entry.exercise))
    profile = profiles(labs).get(key, "")
    shown = safe_entry(entry)
    pairing = safe(partner_problem(entry.student, entry.partner, store.progress.places()))
    saved = store.progress.of(entry.student, entry.lab).get(key)
    if saved is None:
        return Request(
            shown,
            title,
            None,
            None,
            "nothing saved for this exercise yet",
            profile=profile,
            partner_problem=pairing,
        )
    try:
        progress = ExerciseProgress.from_dict(saved)
        safe_progress = ExerciseProgress.from_dict(terminal_safe_data(saved))
    except ValueError as exc:
        return Request(
            shown, title, None, None, safe(str(exc)), profile=profile, partner_problem=pairing
        )
    return Request(
        shown,
        title,
        safe_progress,
        evidence_run(safe_progress),
        profile=profile,
        saved=progress,
        partner_problem=pairing,
    )
