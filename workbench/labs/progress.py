"""Where one student (or pair) stands in the labs: each exercise's progress as saved and as
checked live, the answers given, the sign-offs, and who drives.

The labs screen (and any other front end, and the tests) keeps a :class:`LabProgress` and
asks it everything: reading what the store saved (:func:`read_work`, which touches nothing
but the store and waits for it, so a front end runs it off its event loop, then
:meth:`LabProgress.take_work`; :attr:`LabProgress.reading` until then), setting an
exercise up (:meth:`LabProgress.set_up`), checking it against the station and saving what
changed (:meth:`LabProgress.check`, :meth:`LabProgress.save`), and what a sign-off changes.

An objective passes only on its exercise's own work (:mod:`.checks`), and its pass keeps the
evidence: :func:`evidence_words` says it in one line, and :func:`signoff_driver` names the
person whose work the sign-off rests on.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Literal

from workbench.control.station import LabStation
from workbench.sim.profiles import PROFILES

from .behaviour import BehaviourJudge
from .checks import (
    ExerciseProgress,
    ObjectiveState,
    SetupChanges,
    apply_setup,
    evaluate,
    keep_passed,
)
from .evidence_text import programs_of
from .model import Exercise, Lab
from .store.store import Store, StoreUnavailable

#: (lab id, exercise id)
ExerciseKey = tuple[str, str]
#: how an exercise stands in the list: signed off, its objectives all pass, or neither
Mark = Literal["signed", "passed", "open"]


@dataclass(frozen=True)
class SignedOff:
    """The last sign-off of an exercise: by whom and when (UTC ISO 8601)."""

    instructor: str
    signed_at: str

    def words(self) -> str:
        """``by Dr Chen on 2026-03-02 10:00 UTC``."""
        when = self.signed_at.replace("T", " ").rstrip("Z")[:16]
        return f"by {self.instructor} on {when} UTC" if when else f"by {self.instructor}"


@dataclass
class SavedProgress:
    """What the store holds for a student (or pair), as read in one go."""

    progress: dict[ExerciseKey, ExerciseProgress] = field(default_factory=dict)
    signed: dict[ExerciseKey, SignedOff] = field(default_factory=dict)
    drivers: dict[ExerciseKey, str] = field(default_factory=dict)
    #: exercises ("lab/exercise") whose saved progress could not be read (they start afresh)
    damaged: list[str] = field(default_factory=list)
    #: answers ("lab/exercise question") longer than is kept, cut as they were read
    cut: list[str] = field(default_factory=list)


def read_saved(store: Store, student: str, partner: str = "") -> SavedProgress:
    """The saved progress, sign-offs and drivers of ``student`` (with ``partner``). Passes
    saved without the evidence of their work read as "needs redoing". Raises what the store
    raises (:class:`~.store.StoreUnavailable` while a course database is away)."""
    rows = store.progress.of(student)
    signoffs = store.signoffs.of(student=student)
    drivers = store.progress.drivers(student, partner)
    out = SavedProgress(drivers=drivers)
    for key, data in rows.items():
        try:
            progress = ExerciseProgress.from_dict(data)
        except ValueError:
            out.damaged.append("/".join(key))
            continue
        out.cut += [f"{'/'.join(key)} {question}" for question in progress.cut]
        out.progress[key] = progress
    out.signed = {(r.lab, r.exercise): SignedOff(r.instructor, r.signed_at) for r in signoffs}
    return out


@dataclass(frozen=True)
class SavedWork:
    """What the labs read from the store as they open (:func:`read_work`): the saved progress
    and the exercise the student had open last, or why they could not be read."""

    saved: SavedProgress | None = None
    place: ExerciseKey | None = None
    #: the course database cannot be reached, or did not answer within its deadline: the
    #: work goes on as with a database that is down, and is read again once it is back
    away: bool = False
    #: why the saved progress could not be read otherwise ("" when it was, or when away)
    error: str = ""


def read_work(store: Store, student: str, partner: str = "") -> SavedWork:
    """Everything the labs read from the store as they open: :func:`read_saved` and the
    student's last place. Never raises: a store that is away (or did not answer within its
    deadline) or damaged is said in the result. It waits for the store, up to the store's
    deadline, so a front end calls it off its event loop."""
    try:
        saved = read_saved(store, student, partner)
    except StoreUnavailable:
        return SavedWork(away=True)
    except Exception as exc:  # a damaged database must not stop the lab
        return SavedWork(error=str(exc))
    try:
        place = store.progress.place(student)
    except Exception:  # where the student was is a convenience, never a reason to fail
        place = None
    return SavedWork(saved, place)


def shown_values(station: LabStation) -> dict[str, str]:
    """What the station's screen shows that a question may accept (see ``model.SHOWN``)."""
    port = station.tcp_port
    return {"viple-tcp-port": str(port)} if port is not None else {}


@dataclass
class LabProgress:
    """One student's (or pair's) progress through the labs, in one app."""

    student: str
    partner: str = ""
    #: the progress last saved (or read back) for each exercise
    saved: dict[ExerciseKey, ExerciseProgress] = field(default_factory=dict)
    answers: dict[ExerciseKey, dict[str, str]] = field(default_factory=dict)
    #: how many answers each question of each exercise has been given
    tries: dict[ExerciseKey, dict[str, int]] = field(default_factory=dict)
    signed: dict[ExerciseKey, SignedOff] = field(default_factory=dict)
    #: who drove (or drives) each exercise, as recorded
    drivers: dict[ExerciseKey, str] = field(default_factory=dict)
    #: who of the pair drives now, as far as the workbench knows
    driver: str = ""
    #: the saved work is being read (:func:`read_work`): a front end opens no exercise (so
    #: checks and saves nothing over that work) until :meth:`take_work` has it
    reading: bool = False
    #: compares a student's machine with an exercise's reference (``fsm-behaviour``), made
    #: at the first check with the station's file rules
    judge: BehaviourJudge | None = field(default=None, compare=False, repr=False)

    def __post_init__(self) -> None:
        self.driver = self.driver or self.student

    # -- what the store holds --------------------------------------------------------------
    def take(self, loaded: SavedProgress) -> None:
        """Take what :func:`read_saved` read (on the thread that uses this progress)."""
        for key, progress in loaded.progress.items():
            self.saved[key] = progress
            self.answers[key] = dict(progress.answers)
            self.tries[key] = dict(progress.tries)
        self.signed.update(loaded.signed)
        self.drivers.update(loaded.drivers)

    def take_work(self, work: SavedWork) -> None:
        """Take what :func:`read_work` read (on the thread that uses this progress); the
        reading is over, whether or not the store could give it."""
        self.reading = False
        if work.saved is not None:
            self.take(work.saved)

    def mark(self, key: ExerciseKey) -> Mark:
        if key in self.signed:
            return "signed"
        saved = self.saved.get(key)
        return "passed" if saved is not None and saved.passed else "open"

    # -- doing an exercise -----------------------------------------------------------------
    def open(self, key: ExerciseKey) -> str:
        """The exercise ``key`` is chosen: its recorded driver (else whoever drove last)
        drives it. Returns that driver."""
        self.driver = self.drivers.get(key, self.driver)
        return self.driver

    def set_up(self, station: LabStation, lab: Lab, exercise: Exercise) -> SetupChanges:
        """The exercise's one-key set-up, which begins its attempt; the exercise's driver is
        at the station from now on (the work is recorded as theirs)."""
        station.person = self.open((lab.id, exercise.id))
        return apply_setup(station, exercise.setup, lab=lab.id, exercise=exercise.id)

    def answer(
        self, key: ExerciseKey, question: str, text: str, max_tries: int | None = None
    ) -> bool:
        """One try at ``question``: ``text`` is kept as its answer and counted, unless it is
        empty or the answer kept already (nothing new tried). With ``max_tries``, a question
        whose tries are used up takes no more answers. True when the answer was taken."""
        if not self.can_answer(key, question, max_tries):
            return False
        answers = self.answers.setdefault(key, {})
        if not text.strip() or text.strip() == answers.get(question, "").strip():
            return False
        answers[question] = text
        tries = self.tries.setdefault(key, {})
        tries[question] = tries.get(question, 0) + 1
        return True

    def tries_of(self, key: ExerciseKey, question: str) -> int:
        """How many answers ``question`` of exercise ``key`` has been given."""
        return self.tries.get(key, {}).get(question, 0)

    def can_answer(self, key: ExerciseKey, question: str, max_tries: int | None) -> bool:
        """Whether ``question`` takes another answer (False once its tries are used up)."""
        return max_tries is None or self.tries_of(key, question) < max_tries

    def check(self, lab_id: str, exercise: Exercise, station: LabStation) -> ExerciseProgress:
        """The exercise checked against its own work on the station now, with every pass
        saved before kept (and every pass saved without evidence still needing redoing)."""
        key = (lab_id, exercise.id)
        exercise = exercise.with_shown(shown_values(station))
        if self.judge is None:
            self.judge = BehaviourJudge(station.files)
        live = evaluate(
            lab_id,
            exercise,
            station,
            self.answers.get(key, {}),
            self.tries.get(key, {}),
            self.judge,
        )
        return keep_passed(self.saved.get(key), live)

    def changed(self, progress: ExerciseProgress) -> bool:
        """Worth a save: never saved, an objective passed or failed (or came to need redoing),
        or an answer changed."""
        saved = self.saved.get((progress.lab, progress.exercise))
        if saved is None:
            return True

        def states(p: ExerciseProgress) -> list[tuple[str, bool, bool]]:
            return [(o.text, o.passed, o.redo) for o in p.objectives]

        return (
            states(saved) != states(progress)
            or saved.answers != progress.answers
            or saved.tries != progress.tries
        )

    def save(self, store: Store | None, progress: ExerciseProgress) -> bool:
        """Keep ``progress`` as the exercise's, and write it to ``store``: True when written
        (or on its way), False when kept pending. Raises what the store raises."""
        self.saved[(progress.lab, progress.exercise)] = progress
        if store is None:
            return True
        return store.progress.save(
            self.student, progress.lab, progress.exercise, progress.as_dict()
        )

    # -- sign-off --------------------------------------------------------------------------
    def signoff_driver(self, progress: ExerciseProgress) -> str:
        """Who the sign-off of ``progress`` names as the driver (:func:`signoff_driver`)."""
        people = {self.student, self.partner} - {""}
        return signoff_driver(progress, people) or self.driver

    def signed_off(self, key: ExerciseKey, instructor: str, signed_at: str, driver: str) -> None:
        """A sign-off of ``key`` was saved, naming ``driver``."""
        self.signed[key] = SignedOff(instructor, signed_at)
        self.drivers[key] = driver

    def next_driver(self, lab: Lab, exercise: Exercise, driver: str) -> ExerciseKey | None:
        """``driver`` was chosen to drive next: they drive now, and the exercise after
        ``exercise`` is theirs. Returns that exercise (None after the lab's last) for the
        caller to record (:meth:`Store.progress.set_driver`)."""
        self.driver = driver
        ids = [ex.id for ex in lab.exercises]
        place = ids.index(exercise.id) + 1
        if place >= len(ids):
            return None
        following = (lab.id, ids[place])
        self.drivers[following] = driver
        return following


def signoff_driver(progress: ExerciseProgress, people: set[str]) -> str:
    """The person whose work the sign-off rests on: the one who was at the station for the
    evidence run (the run :class:`~.signoff_record.Evidence` keeps), else for the first other
    passed objective's work; "" when the evidence names nobody of ``people``."""
    passed = [o for o in progress.objectives if o.passed]
    runs = [o.evidence for o in passed if o.evidence.get("record") and o.evidence.get("run")]
    runs += [o.evidence for o in passed if o.evidence.get("run")]
    for ev in runs:
        if ev.get("person") in people:
            return str(ev["person"])
    for o in passed:
        ev = o.evidence
        named = [ev.get("person"), *(ev.get("people") or [])]
        named += [r.get("person") for r in ev.get("runs") or [] if isinstance(r, Mapping)]
        for person in named:
            if person in people:
                return str(person)
    return ""


def questions_words(ev: Mapping[str, Any]) -> str:
    """``5 of 5 right; tries: base 1, margin 3`` (the tries where evidence keeps them), with
    ``; waiting for the instructor: ...`` for questions whose tries are used up."""
    words = f"{ev.get('correct', 0)} of {ev.get('of', 0)} right"
    tries = ev.get("tries")
    if isinstance(tries, Mapping) and tries:
        words += "; tries: " + ", ".join(f"{q} {n}" for q, n in tries.items())
    waiting = ev.get("waiting")
    if waiting:
        words += f"; waiting for the instructor: {', '.join(map(str, waiting))}"
    return words


def signoff_words(progress: ExerciseProgress) -> str:
    """What a sign-off should know beyond the objectives' marks, in one line ("" for
    nothing): the program the evidence rests on (or that it mixes programs), and the
    questions whose tries are used up and wait for the instructor."""
    parts = []
    programs = programs_of(progress)
    named = [f"{name} sha256 {digest[:12]}" for digest, name in programs.items()]
    if len(named) == 1:
        parts.append(f"program {named[0]}")
    elif named:
        parts.append(f"the evidence mixes {len(named)} programs: {', '.join(named)}")
    waiting = [
        str(q)
        for o in progress.objectives
        if o.kind == "questions"
        for q in o.evidence.get("waiting") or []
    ]
    if waiting:
        parts.append(f"out of tries, for you to judge: {', '.join(waiting)}")
    return "; ".join(parts)


def _unit(profile: str) -> str:
    known = PROFILES.get(profile)
    return known.unit if known is not None else ""


def _length(value: object, unit: str) -> str:
    """A distance in the profile's unit: whole pixels, one decimal of a metre-like unit."""
    if not isinstance(value, int | float):
        return "?"
    figure = f"{value:.0f}" if unit == "px" else f"{value:.1f}"
    return f"{figure} {unit}" if unit else figure


def run_figures(metrics: Mapping[str, Any], profile: str) -> str:
    """A run's measures with their units: ``42.1 s, 9.1 unit (4.5 blocks), 450 deg turned,
    0 collisions`` (the time to the exit, else the time it ran)."""
    took = metrics.get("exit_time")
    if not isinstance(took, int | float):
        took = metrics.get("sim_time")
    parts = [f"{took:.1f} s" if isinstance(took, int | float) else "? s"]
    length = _length(metrics.get("distance"), _unit(profile))
    blocks = metrics.get("distance_cells")
    parts.append(f"{length} ({blocks:.1f} blocks)" if isinstance(blocks, int | float) else length)
    if isinstance(metrics.get("turn_degrees"), int | float):
        parts.append(f"{metrics['turn_degrees']:.0f} deg turned")
    collisions = metrics.get("collisions")
    if isinstance(collisions, int):
        parts.append(f"{collisions} collision{'' if collisions == 1 else 's'}")
    return ", ".join(parts)


def evidence_words(state: ObjectiveState, profile: str = "") -> str:
    """What a pass rests on, in one short line ("" for none): the run (its driver, who was at
    the station, its measures with the units of its profile, its record and digest), the
    edit, the keys or the VIPLE program (how far it drove). ``profile``: the exercise's, for
    evidence that does not name its own."""
    ev: Mapping[str, Any] = state.evidence
    if not state.passed or not ev:
        return ""
    if state.kind == "questions":
        return questions_words(ev)
    by = f" by {ev['person']}" if ev.get("person") else ""
    if "run" in ev:
        words = f"run {ev['run']}{by} ({ev.get('driver', '')})"
        metrics = ev.get("metrics")
        if isinstance(metrics, Mapping) and metrics:
            words += f": {run_figures(metrics, str(ev.get('profile', profile)))}"
        if ev.get("record"):
            sha = ev.get("record_sha256") or "unreadable"
            words += f"; record {Path(str(ev['record'])).name} sha256 {str(sha)[:12]}"
    elif "edit" in ev:
        words = f"edit {ev['edit']}{by}: {ev.get('maze', '')} {str(ev.get('maze_digest'))[:12]}"
    elif "runs" in ev:
        runs = ", ".join(f"{r.get('algorithm')} run {r.get('run')}" for r in ev["runs"])
        words = f"runs {runs}"
    elif "motions" in ev:
        words = f"VIPLE {ev.get('role')} at {ev.get('peer')}{by}: {', '.join(ev['motions'])}"
    elif "keys_used" in ev:
        people = ", ".join(ev.get("people") or [])
        words = f"keys {' '.join(ev['keys_used'])} on {ev.get('profile')}"
        words += f" by {people}" if people else ""
    elif "role" in ev:
        unit = _unit(str(ev.get("profile", profile)))
        distance = _length(ev.get("distance"), unit)
        words = f"VIPLE {ev['role']} at {ev.get('peer')}{by} drove {distance}"
        if isinstance(ev.get("turn_degrees"), int | float):
            words += f", turned {ev['turn_degrees']:.0f} deg"
    elif "sensors" in ev:
        words = f"sensors {', '.join(ev['sensors'])}{by}"
    else:
        words = ""
    return words
