"""The labs screen: the course's lab exercises, their instructions and their live checks.

On the left, every lab and its exercises (✓ once an exercise's objectives pass, ★ once an
instructor has signed it off; ``[X]`` and ``[*]`` in ASCII mode); on the right, the chosen
exercise: its instructions, its objectives with ✓/✗ (``[X]``/``[ ]``) and a one-line reason
that follow the station as the student works, and its questions (a multiple-choice one's
choices picked with the arrows and enter or a click, any other typed in its field and tried
with enter; each try is counted, shown under the question, and a question out of tries takes no
more answers); under a passed objective, the work it rests on. The list has the focus whenever
the screen comes up, so its keys never land in an answer: ``a`` puts the exercise's set-up on
the station, ``r`` asks for sign-off (the exercise joins the store's sign-off queue, which the
instructor's console shows; the screen follows the request), and ``i`` opens the instructor's
sign-off at this station where signing here is allowed (not in a served student's session,
whose terminal is the student's). What the student has done is held by :class:`LabProgress` (in
the core): the screen draws it and routes the student's input to it. Progress is saved in the
store as soon as an exercise is opened and each time an objective or an answer changes; an
objective that passed once stays passed, with its evidence, after a restart. The saved work is
read in a thread as the screen comes up (a course database may be slow, or hang until its
deadline): until it is read the screen says so and opens no exercise, so nothing is saved over
it.
"""

from __future__ import annotations

import asyncio
from collections.abc import Callable
from typing import Any, ClassVar, NamedTuple

from textual import events, on
from textual.app import ComposeResult
from textual.binding import BindingType
from textual.containers import Horizontal, Vertical, VerticalScroll
from textual.message import Message
from textual.screen import Screen
from textual.timer import Timer
from textual.widget import Widget
from textual.widgets import Input, Markdown, OptionList, RadioSet, Static
from textual.widgets.option_list import Option

from workbench.control.station import LabStation
from workbench.labs.attempt_work import work_at_stake
from workbench.labs.checks import MAX_ANSWER, ExerciseProgress, SetupChanges
from workbench.labs.course_store import (
    Away,
    Back,
    CourseStore,
    Opened,
    SaveRefused,
    Store,
    StoreEvent,
)
from workbench.labs.model import Exercise, Lab, LabFileError, Question, Setup, load_labs
from workbench.labs.progress import (
    LabProgress,
    SavedWork,
    SignedOff,
    evidence_words,
    read_work,
    shown_values,
)
from workbench.labs.signoff.signoff_record import SignoffRecord
from workbench.sim.session import Snapshot

from ..host import FollowsUnicode, SetUpDone, ShowsSnapshot
from ..keys import LABS_KEY_IDS, bindings
from ..plain import follow_app, prose
from ..serving.single_layout import SingleLayout
from ..widgets.choices import Choices
from ..widgets.field import Field
from ..widgets.key_bar import KeyBar
from ..widgets.signoff_status import SignoffStatus


class Marks(NamedTuple):
    """How an objective, an answer or an exercise in the list is marked."""

    passed: str
    failed: str
    open: str
    #: the lab list's mark of an exercise an instructor has signed off (apart from passed)
    signed: str


UNICODE_MARKS = Marks("✓", "✗", "·", "★")
#: ASCII mode: a ticked box for passed, an empty one for not yet, a star for signed off
ASCII_MARKS = Marks("[X]", "[ ]", "[ ]", "[*]")
PASS, FAIL, OPEN, SIGNED = UNICODE_MARKS


UNREACHABLE = "the course database cannot be reached"
BACK = "the course database is back: your progress is saved"
#: what the screen says of the course store's news that it only says
NEWS_WORDS: dict[type, Callable[[Any], str]] = {
    Away: lambda away: (
        f"{UNREACHABLE}: your progress is kept here ({away.pending} change(s)) and saved as "
        "soon as it is back"
    ),
    SaveRefused: lambda refused: f"progress not saved: {refused.error}",
}
#: what the screen shows until the saved work is read
LOADING = "loading saved work…"
#: how often the screen looks again while an FSM is compared with its reference, seconds
JUDGING_POLL = 0.25


def speed_words(speed: float | None) -> str:
    return "max" if speed is None else f"{speed:g}x"


def setup_words(changes: SetupChanges, setup: Setup) -> list[str]:
    """What a set-up changed besides the profile, maze and sensors, in the message line's
    words."""
    said = []
    if changes.speed is not None:
        speed, speed_was = changes.speed[1], changes.speed[0]
        said.append(f"speed {speed_words(speed)} (was {speed_words(speed_was)})")
    if changes.algorithm is not None:
        name, name_was = changes.algorithm[1], changes.algorithm[0]
        said.append(f"algorithm {name or 'none'} (was {name_was or 'none'})")
    if changes.params_reset:
        whose = "the starter's" if setup.controller.starter is not None else "its own"
        said.append(f"parameters back to {whose} for {setup.profile}")
    if changes.program_dropped:
        said.append(f"program {changes.program_dropped} no longer chosen")
    return said


class StoreNews(Message, bubble=False):
    """What the course store did (:mod:`workbench.labs.course_store`), brought by the app
    (which subscribes to the store's news) from the store's threads to its event loop, and
    handed on to this screen: it goes to the one it is posted to only."""

    def __init__(self, event: StoreEvent) -> None:
        super().__init__()
        self.event = event


class LabsScreen(ShowsSnapshot, FollowsUnicode, SingleLayout, Screen[None]):
    """Choose an exercise, set it up, watch its objectives, answer its questions."""

    DEFAULT_CSS = """
    LabsScreen #labs-body {
        height: 1fr;
    }
    LabsScreen #labs-list {
        width: 28;
        height: 1fr;
    }
    LabsScreen #labs-exercise {
        width: 1fr;
        height: 1fr;
        padding: 0 0 0 1;
    }
    LabsScreen #labs-scroll {
        height: 1fr;
    }
    LabsScreen #labs-title {
        height: auto;
        text-style: bold;
        color: $text-primary;
    }
    LabsScreen #labs-instructions {
        margin: 0;
        padding: 0;
        height: auto;
    }
    LabsScreen #labs-objectives {
        height: auto;
        margin-bottom: 1;
    }
    LabsScreen #labs-questions {
        height: auto;
    }
    LabsScreen .question {
        height: auto;
    }
    LabsScreen .question-text {
        height: auto;
    }
    LabsScreen .question Input {
        width: 1fr;
    }
    LabsScreen .question-reason {
        color: $text-muted;
    }
    LabsScreen #labs-message {
        height: auto;
        max-height: 4;
        padding: 0 1;
        color: $text-warning;
    }
    """

    BINDINGS: ClassVar[list[BindingType]] = [*bindings(*LABS_KEY_IDS)]

    def __init__(
        self,
        station: LabStation,
        student: str,
        partner: str = "",
        labs: list[Lab] | None = None,
        signs_here: bool = True,
        course: CourseStore | None = None,
    ) -> None:
        """The screen shows the labs at once and the saved work once it is read: the store
        comes with the course store's news (:class:`StoreNews`, its ``Opened`` first), which
        the screen says; it tells ``course`` when a save was kept. ``signs_here``: an
        instructor may sign off at this station (``i``); False in a served student's session,
        where only the ready key asks for sign-off."""
        super().__init__()
        self.signs_here = signs_here
        self.course = course
        #: what the screen does with the news of the course store that is not only said
        self._news: dict[type, Callable[[Any], None]] = {
            Opened: self._store_opened,
            Back: self._store_back,
        }
        self.station = station
        self.store: Store | None = None
        self.student = student
        self.partner = partner
        #: what the student (or pair) has done in the labs (read from the store first)
        self.lab_progress = LabProgress(student, partner, reading=True)
        self._problem = ""
        #: the timer that looks again while a machine is compared (None: none waiting)
        self._judging: Timer | None = None
        if labs is None:
            try:
                labs = load_labs()
            except LabFileError as exc:
                labs = []
                self._problem = str(exc)
        self.labs = labs
        self._store_problem = ""
        self._ready = False
        self.selected: tuple[Lab, Exercise] | None = None
        self.progress: ExerciseProgress | None = None
        #: the saved work could not be read: it is read again when the database is back
        self._reload_when_back = False
        #: a sign-off seen while another screen was over this one
        self._signed_later: SignoffStatus.Signed | None = None
        self.unicode = False

    def check_action(self, action: str, parameters: tuple[object, ...]) -> bool | None:
        """A served student's session has no signing here: its key is neither shown nor
        offered in the command palette (``r`` asks for sign-off at the console)."""
        return self.signs_here or action != "sign_off"

    @property
    def driver(self) -> str:
        """Who of the pair drives now, as far as the workbench knows."""
        return self.lab_progress.driver

    # -- store ---------------------------------------------------------------------------
    @on(StoreNews)
    def _store_news(self, message: StoreNews) -> None:
        event = message.event
        handler = self._news.get(type(event))
        if handler is not None:
            handler(event)
        elif type(event) in NEWS_WORDS:
            self.say(NEWS_WORDS[type(event)](event))

    def _store_opened(self, opened: Opened) -> None:
        """The store is open (or could not be): read the saved work from it, in a thread."""
        self.store = opened.store
        self._store_problem = opened.problem
        self.student, self.partner = opened.student, opened.partner
        self.lab_progress = LabProgress(self.student, self.partner, reading=True)
        if self.store is None:
            self._take_work(SavedWork())
            return
        self.query_one(SignoffStatus).use(self.store)
        self.run_worker(self._read_work(), group="labs-read", exit_on_error=False)

    async def _read_work(self, again: bool = False) -> None:
        """Read the saved work off the event loop (a course database that hangs makes the
        read wait for the store's deadline; the app answers keys meanwhile), then show it;
        ``again``: read once the database is back, after it was away when the screen came up
        (what this session changed meanwhile was written first, so it reads back as it is
        here)."""
        store = self.store
        assert store is not None
        work = await asyncio.to_thread(read_work, store, self.student, self.partner)
        if not again:
            self._take_work(work)
        elif work.away:  # still away: read again when it is back
            if self.course is not None:
                self.course.read_away()
        else:
            self._reload_when_back = False
            self.lab_progress.take_work(work)
            self._store_problem = self._work_problem(work)
            self._refresh_list()
            self.say(BACK)

    def _take_work(self, work: SavedWork) -> None:
        """The saved work was read (or could not be): the list, the exercise the student had
        open last and what went wrong show it."""
        self.lab_progress.take_work(work)
        self._store_problem = self._work_problem(work) or self._store_problem
        if work.away:
            self._reload_when_back = True
            if self.course is not None:
                self.course.read_away()
        if not self._ready:
            return
        self._refresh_list()
        listing = self.query_one("#labs-list", OptionList)
        place = self._place(work)
        if place is not None and listing.highlighted == self._first_option():
            # the student had not moved yet: the labs reopen where they were
            listing.highlighted = listing.get_option_index(place)
        self._catch_up()
        self._show_title()
        self.say(self._problem or self._store_problem)

    def _work_problem(self, work: SavedWork) -> str:
        if work.away:
            return (
                f"{UNREACHABLE}: saved progress is not shown yet; what you do now is kept "
                "and saved when it is back"
            )
        if work.error:
            return f"cannot read saved progress: {work.error}"
        if work.saved is None:
            return ""
        damaged, cut = work.saved.damaged, work.saved.cut
        if damaged:
            return f"saved progress unreadable (starts afresh): {', '.join(damaged)}"
        if cut:
            return (
                f"saved answers longer than {MAX_ANSWER} characters were cut to their first "
                f"{MAX_ANSWER}: {', '.join(cut[:3])}{' ...' if len(cut) > 3 else ''}"
            )
        return ""

    def _save(self, progress: ExerciseProgress) -> None:
        try:
            saved = self.lab_progress.save(self.store, progress)
        except Exception as exc:
            self.say(f"progress not saved: {exc}")
            return
        if not saved and self.course is not None:
            self.course.kept()

    def _store_back(self, back: Back) -> None:
        """Everything kept here is written (the course store tried it again); saved work that
        could not be read is read now."""
        if self._reload_when_back:
            self.run_worker(self._read_work(again=True), group="labs-read", exit_on_error=False)
        else:
            self.say(BACK)

    # -- layout --------------------------------------------------------------------------
    def compose(self) -> ComposeResult:
        with Horizontal(id="labs-body"):
            yield OptionList(*self._options(), id="labs-list", markup=False)
            with Vertical(id="labs-exercise"):
                yield Static("", id="labs-title", markup=False)
                # objectives scroll with the text: every one stays reachable, however many
                with VerticalScroll(id="labs-scroll"):
                    yield Static("", id="labs-objectives", markup=False)
                    yield Markdown("", id="labs-instructions")
                    yield Vertical(id="labs-questions")
        yield SignoffStatus(self.store, id="labs-signoff")
        yield Static("", id="labs-message", markup=False)
        yield KeyBar()

    @property
    def marks(self) -> Marks:
        return UNICODE_MARKS if self.unicode else ASCII_MARKS

    def _options(self) -> list[Option]:
        options: list[Option] = []
        marks = self.marks
        for lab in self.labs:
            options.append(
                Option(prose(lab.title, self.unicode), id=f"lab:{lab.id}", disabled=True)
            )
            for ex in lab.exercises:
                mark = {"signed": marks.signed, "passed": marks.passed, "open": marks.open}[
                    self.lab_progress.mark((lab.id, ex.id))
                ]
                title = prose(ex.title, self.unicode)
                options.append(Option(f"{mark} {title}", id=f"{lab.id}/{ex.id}"))
        return options

    def set_unicode(self, unicode: bool) -> None:
        self.unicode = unicode
        if not self._ready:
            return
        self._refresh_list()
        if self.selected is not None:
            lab, exercise = self.selected
            self.selected = None
            self._show_exercise(lab, exercise)

    def on_mount(self) -> None:
        self.unicode = getattr(self.app, "unicode", True)
        follow_app(self)
        self._ready = True
        self._refresh_list()
        listing = self.query_one("#labs-list", OptionList)
        listing.highlighted = self._first_option()
        listing.focus()
        if self.lab_progress.reading:
            self._show_title()
            self.say(self._problem)
        else:  # read before the screen came up: shown now
            self._take_work(SavedWork())

    def _first_option(self) -> int | None:
        listing = self.query_one("#labs-list", OptionList)
        return next((i for i, o in enumerate(listing.options) if not o.disabled), None)

    def _place(self, work: SavedWork) -> str | None:
        """The option of the exercise the student had open last (None: not known)."""
        if work.place is None:
            return None
        option = "/".join(work.place)
        known = {f"{lab.id}/{ex.id}" for lab in self.labs for ex in lab.exercises}
        return option if option in known else None

    def on_screen_resume(self) -> None:
        # back on the list, whatever had the focus before: the screen's keys (a, i) never
        # land in an answer; an answer takes keys only once the student moves to it
        self.query_one("#labs-list", OptionList).focus()
        self._objectives_in_view()
        self.show_snapshot(self.station.snapshot())
        later, self._signed_later = self._signed_later, None
        if later is not None:
            self._signed_elsewhere(later)

    def on_descendant_focus(self, event: events.DescendantFocus) -> None:
        if event.widget.id == "labs-list":  # back from an answer: the objectives again
            self._objectives_in_view()

    def _objectives_in_view(self) -> None:
        """The exercise pane back at its top, where the objectives are (it stays where an
        answer scrolled it otherwise, the objectives out of sight)."""
        self.query_one("#labs-scroll", VerticalScroll).scroll_home(animate=False)

    def _refresh_list(self) -> None:
        # each option's text replaced where it is: the list keeps its highlight and scroll,
        # and measures the new texts at the width it has now (options cleared and added
        # again were measured without the scroll bar they bring back)
        listing = self.query_one("#labs-list", OptionList)
        for option in self._options():
            listing.replace_option_prompt(option.id or "", option.prompt)

    # -- choosing ------------------------------------------------------------------------
    @on(OptionList.OptionHighlighted, "#labs-list")
    def _chosen(self, event: OptionList.OptionHighlighted) -> None:
        self._show_option(event.option.id or "")

    def _catch_up(self) -> None:
        """Show the exercise the list has highlighted now: a key typed right after the one
        that moved the highlight acts on the exercise it moved to, though the list's message
        saying so is still on its way."""
        option = self.query_one("#labs-list", OptionList).highlighted_option
        if option is not None:
            self._show_option(option.id or "")

    def _show_option(self, option_id: str) -> None:
        if "/" not in option_id:
            return
        lab_id, ex_id = option_id.split("/", 1)
        lab = next(lab for lab in self.labs if lab.id == lab_id)
        self._show_exercise(lab, lab.exercise(ex_id))

    def _show_exercise(self, lab: Lab, exercise: Exercise) -> None:
        if self.selected == (lab, exercise) or self.lab_progress.reading:
            return  # (an exercise opens once the saved work is read: nothing is saved over it)
        self.selected = (lab, exercise)
        if self.store is not None:
            try:
                placed = self.store.progress.set_place(self.student, lab.id, exercise.id)
                if not placed and self.course is not None:
                    self.course.kept()
            except Exception as exc:
                self.say(f"cannot save where you are: {exc}")
        driver = self.lab_progress.open((lab.id, exercise.id))
        self.query_one(SignoffStatus).follow(
            self.student, self.partner, driver, lab.id, exercise.id
        )
        self.progress = None
        self._show_title()
        unicode = self.unicode
        self.query_one("#labs-instructions", Markdown).update(prose(exercise.instructions, unicode))
        box = self.query_one("#labs-questions", Vertical)
        listing = self.query_one("#labs-list", OptionList)
        if self.focused is not None and box in self.focused.ancestors:
            listing.focus()  # not onto whatever follows the answer that goes
        box.remove_children()
        answers = self.lab_progress.answers.get((lab.id, exercise.id), {})
        for q in exercise.questions:
            answer_box = self._answer_widget(q, answers.get(q.id, ""))
            answer_box.disabled = not self.lab_progress.can_answer(
                (lab.id, exercise.id), q.id, q.max_tries
            )
            box.mount(
                Vertical(
                    Static(prose(q.text, unicode), markup=False, classes="question-text"),
                    answer_box,
                    Static(
                        self._answer_reason(exercise, q.id),
                        classes="question-reason",
                        markup=False,
                    ),
                    classes="question",
                )
            )
        # the exercise opens at the top of its text, its objectives in view
        self.query_one("#labs-scroll", VerticalScroll).scroll_home(animate=False)
        self.show_snapshot(self.station.snapshot())

    def _show_title(self) -> None:
        """The chosen exercise's title, and by whom and when it was signed off (while the
        saved work is read, that it is)."""
        if self.lab_progress.reading:
            self.query_one("#labs-title", Static).update(prose(LOADING, self.unicode))
            return
        if self.selected is None:
            return
        lab, exercise = self.selected
        signed = self.lab_progress.signed.get((lab.id, exercise.id))
        title = f"{lab.title}: {exercise.title}"
        if signed:
            title += f" ({self.marks.signed} signed off {signed.words()})"
        self.query_one("#labs-title", Static).update(prose(title, self.unicode))

    def _answer_widget(self, q: Question, answer: str) -> Field | Choices:
        """A multiple-choice question's choices to pick from, any other question's field
        (neither selects what it holds when it takes the focus: a key typed there adds to it)."""
        if q.choices:
            labels = [prose(choice, self.unicode) for choice in q.choices]
            return Choices(q.choices, labels, answer, id=f"q-{q.id}")
        return Field(
            answer,
            placeholder=q.unit or "answer",
            id=f"q-{q.id}",
            max_length=MAX_ANSWER,
            select_on_focus=False,
        )

    def _answer_reason(self, exercise: Exercise, question_id: str, typed: str = "") -> str:
        """The line under an answer: whether it is right, its tries, and (while a typed
        answer is not yet tried) that enter tries it."""
        lab = self.selected[0] if self.selected else None
        key = (lab.id, exercise.id) if lab else ("", exercise.id)
        answers = self.lab_progress.answers.get(key, {})
        text = answers.get(question_id, "").strip()
        shown = exercise.with_shown(shown_values(self.station))  # (the port it listens on)
        q = next(q for q in shown.questions if q.id == question_id)
        used = self.lab_progress.tries_of(key, question_id)
        locked = not self.lab_progress.can_answer(key, question_id, q.max_tries)
        marks = self.marks
        if typed.strip() and typed.strip() != text and not locked:
            left = f": {q.max_tries - used} of {q.max_tries} tries left" if q.max_tries else ""
            return prose(f"press enter to try this answer{left}", self.unicode)
        if not text:
            return "not answered yet"
        ok, reason = q.check(text)
        if q.max_tries:
            tries = f" (try {used} of {q.max_tries})"
        else:
            tries = f" ({used} {'try' if used == 1 else 'tries'})" if used else ""
        if locked and not ok:
            return prose(
                f"{marks.failed} {reason}{tries}: no tries left, the answer waits for the "
                "instructor",
                self.unicode,
            )
        return prose(f"{marks.passed if ok else marks.failed} {reason}{tries}", self.unicode)

    @on(Input.Changed)
    def _typed(self, event: Input.Changed) -> None:
        """A typed answer is not tried until enter: the line under it says so."""
        field_id = event.input.id or ""
        if not field_id.startswith("q-") or self.selected is None:
            return
        box = event.input.parent
        if box is not None:
            box.query_one(".question-reason", Static).update(
                self._answer_reason(self.selected[1], field_id[2:], event.value)
            )

    @on(Input.Submitted)
    def _submitted(self, event: Input.Submitted) -> None:
        self._answered(event.input, event.value)

    @on(RadioSet.Changed)
    def _picked(self, event: RadioSet.Changed) -> None:
        if isinstance(event.radio_set, Choices):
            self._answered(event.radio_set, event.radio_set.answer)

    def _answered(self, widget: Widget, answer: str) -> None:
        """One try at a question (enter in its field, or a choice picked)."""
        field_id = widget.id or ""
        if not field_id.startswith("q-") or self.selected is None:
            return
        lab, exercise = self.selected
        question_id = field_id[2:]
        q = next(q for q in exercise.questions if q.id == question_id)
        key = (lab.id, exercise.id)
        self.lab_progress.answer(key, question_id, answer, q.max_tries)
        if not self.lab_progress.can_answer(key, question_id, q.max_tries):
            widget.disabled = True
        box = widget.parent
        if box is not None:
            box.query_one(".question-reason", Static).update(
                self._answer_reason(exercise, question_id)
            )
        self.show_snapshot(self.station.snapshot())

    @on(Field.Capped)
    def _answer_too_long(self, event: Field.Capped) -> None:
        if (event.field.id or "").startswith("q-"):
            self.say(f"an answer is at most {event.limit} characters: the rest was not kept")

    # -- live checks ---------------------------------------------------------------------
    def track(self) -> ExerciseProgress | None:
        """Check the chosen exercise against the station (objectives that passed before stay
        passed); save it when it is new or an objective or an answer changed."""
        if self.selected is None:
            return None
        lab, exercise = self.selected
        key = (lab.id, exercise.id)
        progress = self.lab_progress.check(lab.id, exercise, self.station)
        if self.lab_progress.changed(progress):
            mark = self.lab_progress.mark(key)
            self._save(progress)
            if self._ready and self.lab_progress.mark(key) != mark:
                self._refresh_list()
        self.progress = progress
        judge = self.lab_progress.judge
        if judge is not None and judge.busy and self._judging is None:
            # a machine is being compared beside the screen: look again until it is done
            self._judging = self.set_timer(JUDGING_POLL, self._judged)
        return progress

    def _judged(self) -> None:
        self._judging = None
        if self.is_mounted:
            self.show_snapshot(self.station.snapshot())

    def show_snapshot(self, snapshot: Snapshot) -> None:
        if not self._ready:
            return
        progress = self.track()
        if progress is None:
            return
        marks = self.marks
        lines = []
        profile = self.selected[1].setup.profile if self.selected is not None else ""
        for o in progress.objectives:
            lines.append(f"{marks.passed if o.passed else marks.failed} {o.text}: {o.reason}")
            evidence = evidence_words(o, profile)
            if evidence:
                lines.append(f"  {evidence}")
        self.query_one("#labs-objectives", Static).update(prose("\n".join(lines), self.unicode))

    def say(self, message: str) -> None:
        if self._ready:
            self.query_one("#labs-message", Static).update(message)
        else:
            self._problem = message

    # -- actions -------------------------------------------------------------------------
    def action_close(self) -> None:
        self.app.pop_screen()

    def _choose_first(self) -> bool:
        """Whether an exercise is chosen; else the student is told why not."""
        if self.selected is not None:
            return True
        if self.lab_progress.reading:
            self.say(prose(f"{LOADING} a moment, please", self.unicode))
        else:
            self.say("choose an exercise first")
        return False

    def action_apply_setup(self) -> None:
        self._catch_up()
        if not self._choose_first():
            return
        assert self.selected is not None
        lab, exercise = self.selected
        work = work_at_stake(self.station, lab.id, exercise, self.track())
        if work is None:
            self._set_up(lab, exercise)
            return
        from ..dialogs.confirm import ConfirmDialog

        left = len(work.open_objectives)
        lines = [
            f"{exercise.title} is under way: {work.words()} so far.",
            f"A new set-up begins a new attempt, and that work stops counting for the {left} "
            f"objective{'' if left == 1 else 's'} not passed yet (passed ones stay passed, "
            "answers stay).",
        ]
        dialog = ConfirmDialog("Set up again?", lines, "Set up again", "Keep working")
        self.app.push_screen(dialog, lambda yes: self._set_up_again(lab, exercise, yes))

    def _set_up_again(self, lab: Lab, exercise: Exercise, yes: bool | None) -> None:
        if yes:
            self._set_up(lab, exercise)
        else:
            self.say("not set up again: the attempt under way goes on")

    def _set_up(self, lab: Lab, exercise: Exercise) -> None:
        try:
            changes = self.lab_progress.set_up(self.station, lab, exercise)
        except Exception as exc:
            self.say(f"cannot set up {exercise.title}: {exc}")
            return
        setup = exercise.setup
        done = f"set up: {setup.profile}, {setup.maze.path.name}"
        controller = str(setup.controller)
        if changes.algorithm is None or controller != f"algorithm {changes.algorithm[1]}":
            done += f", {controller}"  # (else the algorithm is named with what it replaced)
        self.say("; ".join([done, *setup_words(changes, setup)]))
        self.post_message(SetUpDone(setup))
        self.show_snapshot(self.station.snapshot())

    def action_ready(self) -> None:
        if not self._choose_first():
            return
        if self.store is None:
            self.say(self._store_problem or "no data folder: sign-off is not available")
            return
        self.query_one(SignoffStatus).ask()

    @on(SignoffStatus.Asked)
    def _asked(self, event: SignoffStatus.Asked) -> None:
        if event.problem:
            self.say(event.problem)
        elif event.state is not None and event.state.place is not None:
            self.say(f"asked for sign-off: you are number {event.state.place} in the queue")

    @on(SignoffStatus.Signed)
    def _signed_elsewhere(self, event: SignoffStatus.Signed) -> None:
        """A sign-off made at an instructor's console: the title and the list show it (once
        this screen is shown again, when a dialog or another screen is over it)."""
        if self.app.screen is not self:
            self._signed_later = event
            return
        key = (event.lab, event.exercise)
        if key in self.lab_progress.signed:  # known here already (read at the start, or here)
            return
        signed = SignedOff(event.instructor, event.signed_at)
        self.lab_progress.signed[key] = signed
        self._refresh_list()
        if self.selected is not None and (self.selected[0].id, self.selected[1].id) == key:
            self._show_title()
            self.say(f"signed off {signed.words()}")

    def action_sign_off(self) -> None:
        self._catch_up()
        if not self._choose_first():
            return
        if self.store is None:
            self.say(self._store_problem or "no data folder: sign-off is not available")
            return
        from ..dialogs.signoff import SignoffModal

        progress = self.track()
        assert progress is not None
        already = self.lab_progress.signed.get((progress.lab, progress.exercise))
        self.app.push_screen(
            SignoffModal(
                self.store,
                progress,
                self.student,
                self.partner,
                self.lab_progress.signoff_driver(progress),
                already=already.words() if already is not None else "",
                on_signed=self._record_saved,
            ),
            self._signed_off,
        )

    def _record_saved(self, record: SignoffRecord) -> None:
        """A sign-off was saved: the exercise's title and its mark in the list say so now."""
        key = (record.lab, record.exercise)
        self.lab_progress.signed_off(key, record.instructor, record.signed_at, record.driver)
        self._refresh_list()
        self._show_title()

    def _signed_off(self, driver: str | None) -> None:
        if driver is None or self.selected is None:
            return
        lab, exercise = self.selected
        following = self.lab_progress.next_driver(lab, exercise, driver)
        self.station.person = driver
        if following is not None and self.store is not None:
            try:
                self.store.progress.set_driver(self.student, self.partner, *following, driver)
            except Exception as exc:
                self.say(f"signed off; the next driver was not recorded: {exc}")
                return
        self._refresh_list()
        self.say(f"signed off; {driver} drives next")
