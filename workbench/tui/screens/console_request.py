"""One request for sign-off, opened at the instructor's console: judge it, then sign or decline.

The screen shows the pair, the driver and the exercise, every objective with its reason and its
evidence, and the figures of the run the objectives rest on (``p`` replays that run in the
maze view). The instructor chooses their name, types their passphrase (here, in their own
session: the student's terminal never sees it) and signs (ctrl+s), or writes a note and
declines (ctrl+d), which the student reads on their labs screen. Reading the request, unlocking
the key (scrypt) and writing the record all run in threads; the screen keeps answering.
It returns what was done, in words for the console's message line (None: closed).
"""

from __future__ import annotations

import asyncio
import textwrap
from typing import Any, ClassVar

from textual import on
from textual.app import ComposeResult
from textual.binding import BindingType
from textual.containers import Horizontal, Vertical, VerticalScroll
from textual.screen import Screen
from textual.widgets import Button, Input, Static

from workbench.files.workspace import LOCAL
from workbench.labs.classview import Request, read_request
from workbench.labs.copy_hints import CopyHint, hints_for
from workbench.labs.course_store import QueueEntry, Store, StoreError
from workbench.labs.evidence_text import lines_of_progress, mixed_programs_text, short_digest
from workbench.labs.model import Lab
from workbench.labs.signoff.roster import roster_names
from workbench.labs.signoff.signing import sign_off
from workbench.labs.signoff.signoff_errors import SignoffError
from workbench.sim.record import RecordError
from workbench.sim.replay import load_replay

from ..keys import bindings
from ..picture_saving import save_picture_off_the_loop
from ..plain import follow_app
from ..widgets.field import Field
from ..widgets.key_bar import KeyBar
from ..widgets.signoff_form import READING_ROSTER, SignoffForm


def record_line(run: dict[str, Any] | None) -> str:
    """Where the evidence run's record is, and whether it replays."""
    if run is None:
        return "no run among the evidence"
    record = run.get("record")
    if not record:
        return f"run {run.get('run', '?')} was not recorded (no replay)"
    number = run.get("run", "?")
    return f"run {number} is recorded in {record}: p replays it, ctrl+g saves its picture"


def hanging(lines: list[str], width: int) -> list[str]:
    """``lines`` wrapped to ``width`` columns, each line's rest indented under its words (so
    an objective's evidence stays apart from the next objective); words are never cut."""
    out = []
    for line in lines:
        text = line.lstrip(" ")
        indent = " " * (len(line) - len(text))
        mark = text.split(" ", 1)[0] if text[:1] in "[!✓✗" else ""
        rest = indent + " " * (len(mark) + 1 if mark else 2)
        out += textwrap.wrap(
            line,
            max(width, len(rest) + 10),
            subsequent_indent=rest,
            break_long_words=False,
            break_on_hyphens=False,
        ) or [""]
    return out


def hint_lines(student: str, hints: tuple[CopyHint, ...]) -> list[str]:
    """The copy hints that name ``student``: the program and the other students."""
    return [
        f"same program as {', '.join(others)}: {hint.name} (sha256 {short_digest(hint.digest)})"
        for hint, others in hints_for(student, hints)
    ]


class RequestScreen(Screen[str | None]):
    """Judge one request; sign it off or decline it."""

    DEFAULT_CSS = """
    RequestScreen #request-title {
        height: auto;
        text-style: bold;
        color: $text-primary;
        padding: 0 1;
    }
    RequestScreen #request-scroll {
        height: 1fr;
        padding: 0 1;
    }
    RequestScreen #request-objectives, RequestScreen #request-run {
        height: auto;
    }
    RequestScreen #request-run {
        color: $text-muted;
    }
    RequestScreen #request-sign-off {
        height: auto;
        padding: 0 1;
    }
    RequestScreen #request-sign-off .field-row, RequestScreen #request-sign-off Tick {
        margin-top: 0;
    }
    RequestScreen .button-row {
        height: 1;
    }
    RequestScreen .button-row Button {
        margin-right: 2;
        min-width: 0;
        width: auto;
    }
    RequestScreen #request-status {
        height: auto;
        max-height: 2;
        padding: 0 1;
        color: $text-warning;
    }
    """

    BINDINGS: ClassVar[list[BindingType]] = [
        *bindings(
            "dialog.close", "console.sign", "console.decline", "console.replay", "console.picture"
        )
    ]

    def __init__(
        self,
        store: Store,
        entry: QueueEntry,
        labs: list[Lab],
        hints: tuple[CopyHint, ...] = (),
    ) -> None:
        super().__init__()
        self.store = store
        self.entry = entry
        self.labs = labs
        #: the class's copy hints as the console last read them
        self.hints = hints
        #: what the objectives part says, before it is wrapped to the screen's width
        self._lines: list[str] = []
        self.request: Request | None = None
        #: a sign-off or decline under way (one at a time)
        self.busy = False
        self.done = ""
        #: the instructors one may sign as, read from the store once the screen is up
        self.roster: list[str] = []
        self.roster_problem = ""
        #: the instructor's word on the partner the request names (None: not asked yet)
        self.partner_agrees: bool | None = None

    def compose(self) -> ComposeResult:
        e = self.entry
        yield Static(
            f"{e.pair} ask for sign-off of {e.lab}/{e.exercise}; driver {e.driver or e.student}",
            id="request-title",
            markup=False,
        )
        with VerticalScroll(id="request-scroll"):
            yield Static("reading the saved progress...", id="request-objectives", markup=False)
            yield Static("", id="request-run", markup=False)
        with Vertical(id="request-sign-off"):
            yield SignoffForm(
                "request",
                self.roster,
                note_hint="optional to sign; needed to decline or override",
                override_label="Override: sign although objectives have not passed",
            )
            with Horizontal(classes="button-row"):
                yield Button("Sign off", id="request-sign", variant="primary", compact=True)
                yield Button("Decline", id="request-decline", compact=True)
                yield Button("Replay run", id="request-replay", compact=True)
        yield Static(self.roster_problem, id="request-status", markup=False)
        yield KeyBar()

    def on_mount(self) -> None:
        follow_app(self)
        self.query_one(SignoffForm).focus_first()
        self._say(READING_ROSTER)
        self.run_worker(self._load(), group="request", exit_on_error=False)

    async def _load(self) -> None:
        """Read the roster, then the request, each in a thread (a course database may take
        its time, or not answer)."""
        self.roster, self.roster_problem = await asyncio.to_thread(roster_names, self.store)
        form = self.query_one(SignoffForm)
        form.set_roster(self.roster)
        if not form.entry().passphrase:  # not while the instructor is typing it
            form.focus_first()
        self._say(self.roster_problem)
        try:
            request = await asyncio.to_thread(read_request, self.store, self.entry, self.labs)
        except StoreError as exc:
            self._say(f"cannot read the saved progress: {exc}")
            return
        self.request = request
        self._show(request)

    def _show(self, request: Request) -> None:
        unicode = getattr(self.app, "unicode", False)
        marks = ("✓", "✗") if unicode else ("[X]", "[ ]")
        lines = [f"{request.title}"]
        progress = request.progress
        if progress is None:
            lines.append(request.problem)
        else:
            warnings = [mixed_programs_text(request.programs)]
            entry = self.entry
            for person in (entry.student, entry.partner):
                if person:
                    who = f"{person}: " if entry.partner else ""
                    warnings += [who + line for line in hint_lines(person, self.hints)]
            lines += [f"! {w}" for w in warnings if w]
            lines += lines_of_progress(progress, request.profile, unicode, marks)
            count = sum(o.passed for o in progress.objectives)
            total = len(progress.objectives)
            lines.append(
                "all objectives pass"
                if request.passed
                else f"{count} of {total} objectives pass: signing needs an override and a note"
            )
        self._lines = lines
        self._wrap()
        self.query_one("#request-run", Static).update(record_line(request.run))

    def _wrap(self) -> None:
        scroll = self.query_one("#request-scroll", VerticalScroll)
        width = (
            scroll.size.width or self.app.size.width - 2
        ) - scroll.styles.scrollbar_size_vertical
        text = "\n".join(hanging(self._lines, width))
        self.query_one("#request-objectives", Static).update(text)

    def on_resize(self) -> None:
        if self._lines:
            self._wrap()

    def _say(self, message: str) -> None:
        self.query_one("#request-status", Static).update(message)

    @on(Field.Capped, "#request-note")
    def _note_too_long(self, event: Field.Capped) -> None:
        self._say(f"a note is at most {event.limit} characters: the rest was not kept")

    # -- signing ---------------------------------------------------------------------------
    @on(Input.Submitted, "#request-passphrase")
    @on(Button.Pressed, "#request-sign")
    def action_sign(self) -> None:
        if self.busy or self.done:
            return
        if not self.roster:
            self._say(self.roster_problem or READING_ROSTER)
            return
        request = self.request
        if request is None or request.progress is None:
            self._say(request.problem if request else "the saved progress is still being read")
            return
        form = self.query_one(SignoffForm)
        entry = form.entry()
        instructor = entry.instructor
        if instructor is None:
            self._say("choose the instructor")
            return
        if request.entry.partner and self.partner_agrees is None:
            self._confirm_pair(request)
            return
        self.busy = True
        self._say(f"checking {instructor}'s key...")
        secret = form.take_passphrase()
        self.run_worker(
            self._sign(request, instructor, secret, entry.note, entry.override),
            group="request",
            exit_on_error=False,
        )

    def _confirm_pair(self, request: Request) -> None:
        """Ask whether the partner worked on it and agrees; sign once the instructor says."""
        from ..dialogs.pair import PairDialog

        def chosen(agrees: bool | None) -> None:
            if agrees is None:
                self._say("not signed: say whether the partner is on the sign-off first")
                return
            self.partner_agrees = agrees
            self.action_sign()

        entry = request.entry
        self.app.push_screen(
            PairDialog(entry.student, entry.partner, request.partner_problem), chosen
        )

    async def _sign(
        self, request: Request, instructor: str, passphrase: str, note: str, override: bool
    ) -> None:
        """Check, unlock (scrypt) and sign in a thread; then close the request."""
        store, entry = self.store, self.entry
        try:
            _, record = await asyncio.to_thread(
                sign_off, store, instructor, passphrase, request.fields(self.partner_agrees),
                override, note,
                say=lambda text: self.app.call_from_thread(self._say, text),
            )  # fmt: skip
        except SignoffError as exc:
            self._say(str(exc))
            return
        except Exception as exc:
            self._say(f"not signed: {exc}")
            return
        finally:
            self.busy = False
        problems = []
        try:
            await asyncio.to_thread(store.queue.mark_signed, entry.id, instructor)
        except StoreError as exc:
            problems.append(f"the request stays in the queue: {exc}")
        try:
            await asyncio.to_thread(
                store.progress.set_driver, entry.student, record.partner, entry.lab, entry.exercise,
                record.driver,
            )  # fmt: skip
        except StoreError as exc:
            problems.append(f"the driver was not recorded: {exc}")
        pair = entry.student + (f" and {record.partner}" if record.partner else "")
        self.done = (
            f"signed off {pair} {entry.lab}/{entry.exercise} as {instructor}"
            f"{' (override)' if record.override else ''}"
        )
        self._say("; ".join([self.done, *problems]) + "; escape goes back to the class")

    @on(Input.Submitted, "#request-note")
    @on(Button.Pressed, "#request-decline")
    def action_decline(self) -> None:
        if self.busy or self.done:
            return
        form = self.query_one(SignoffForm)
        entry = form.entry()
        note = entry.note.strip()
        if not note:
            self._say("write a note first: it tells the student what to do before asking again")
            form.focus_note()
            return
        who = entry.instructor or self.app.title or "instructor"
        self.busy = True
        self.run_worker(self._decline(who, note), group="request", exit_on_error=False)

    async def _decline(self, instructor: str, note: str) -> None:
        try:
            await asyncio.to_thread(self.store.queue.decline, self.entry.id, instructor, note)
        except StoreError as exc:
            self._say(f"not declined: {exc}")
            return
        finally:
            self.busy = False
        e = self.entry
        self.done = f"declined {e.pair} {e.lab}/{e.exercise}: {note}"
        self.dismiss(self.done)

    # -- replay ----------------------------------------------------------------------------
    @on(Button.Pressed, "#request-replay")
    def action_replay(self) -> None:
        request = self.request
        run = request.run if request is not None else None
        record = run.get("record") if run else None
        if not record:
            self._say("no recorded run among the evidence: nothing to replay")
            return
        self.run_worker(self._replay(str(record)), group="request", exit_on_error=False)

    def action_picture(self) -> None:
        """Save the evidence run's picture in pictures/ (the instructor's current folder)."""
        request = self.request
        run = request.run if request is not None else None
        record = run.get("record") if run else None
        if not record:
            self._say("no recorded run among the evidence: nothing to draw")
            return
        save_picture_off_the_loop(
            self,
            [str(record)],
            "path",
            LOCAL,
            lambda text, error: self._say(text),
            what=f"run {run.get('run', '?') if run else '?'}",
        )

    async def _replay(self, path: str) -> None:
        from .replay import ReplayScreen

        try:
            replay = await asyncio.to_thread(load_replay, path)
        except (OSError, RecordError) as exc:
            self._say(f"cannot replay the run: {exc}")
            return
        unicode = getattr(self.app, "unicode", False)
        self.app.push_screen(ReplayScreen(path, replay, unicode=unicode))

    def action_close(self) -> None:
        if self.busy:
            self._say("wait: the sign-off is under way")
            return
        self.dismiss(self.done or None)
