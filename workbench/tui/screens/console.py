"""The instructor's console: the class live from the store, and the sign-off queue.

At the top, the requests for sign-off in the order the students asked; below, every student
with the exercise they have open and its objectives (✓/✗, ``[X]``/``[ ]`` in ASCII mode), and
their place in the queue. A thread of the screen's own reads the store about once a second
(:func:`workbench.labs.classview.read_class`), never the event loop: a course database may be
across the network. Enter on a request opens it (:mod:`.console_request`), where the instructor
signs it off with their own key, typed in their own session, or declines it with a note.
"""

from __future__ import annotations

import threading
import time
from typing import ClassVar

from textual import on
from textual.app import ComposeResult
from textual.binding import BindingType
from textual.message import Message
from textual.screen import Screen
from textual.widgets import OptionList, Static
from textual.widgets.option_list import Option

from workbench.labs.classview import ClassView, StudentRow, read_class
from workbench.labs.model import Lab
from workbench.labs.store import Store, StoreUnavailable

from ..host import FollowsUnicode
from ..keys import bindings
from ..plain import follow_app
from ..widgets.key_bar import KeyBar

#: seconds between reads of the store
POLL_SECONDS = 1.0


class ClassRead(Message):
    """One read of the class from the store (posted from the reading thread)."""

    def __init__(self, view: ClassView | None, problem: str = "") -> None:
        super().__init__()
        self.view = view
        self.problem = problem
        #: when the read finished (time.monotonic)
        self.at = time.monotonic()


def objective_marks(row: StudentRow, unicode: bool) -> str:
    passed, failed = ("✓", "✗") if unicode else ("X", ".")
    return "".join(passed if ok else failed for _text, ok in row.objectives) or "-"


def row_text(row: StudentRow, unicode: bool) -> str:
    """One student's line: who, the exercise, the objectives, the queue."""
    who = row.student + (f"+{row.partner}" if row.partner else "")
    if row.signed:
        state = "signed off"
    elif row.waiting is not None:
        state = f"waiting #{row.waiting}"
    elif row.problem:
        state = "progress unreadable"
    else:
        state = ""
    where = f"{row.lab}/{row.exercise}"
    return f"{who[:18]:<18} {where[:30]:<30} {objective_marks(row, unicode):<8} {state}"


class ConsoleScreen(FollowsUnicode, Screen[None]):
    """The class and its sign-off queue, live."""

    DEFAULT_CSS = """
    ConsoleScreen #console-queue-title, ConsoleScreen #console-class-title {
        height: 1;
        text-style: bold;
        color: $text-primary;
        padding: 0 1;
    }
    ConsoleScreen #console-queue {
        height: auto;
        max-height: 8;
        min-height: 3;
    }
    ConsoleScreen #console-class {
        height: 1fr;
    }
    ConsoleScreen #console-message {
        height: auto;
        max-height: 2;
        padding: 0 1;
        color: $text-warning;
    }
    """

    BINDINGS: ClassVar[list[BindingType]] = [*bindings("console.open")]

    def __init__(self, store: Store, labs: list[Lab], instructor: str = "") -> None:
        super().__init__()
        self.store = store
        self.labs = labs
        #: the login the console was opened by (an SSH account), shown in the title
        self.instructor = instructor
        self.view: ClassView | None = None
        #: the message line shows a problem reading the store (cleared once it reads again)
        self._problem_shown = False
        self.unicode = False
        self._stop = threading.Event()
        self._wake = threading.Event()
        #: called with each read, once shown (the bench measures with it)
        self.on_shown: list = []

    def compose(self) -> ComposeResult:
        yield Static("Sign-off queue", id="console-queue-title", markup=False)
        yield OptionList(id="console-queue", markup=False)
        yield Static("Class", id="console-class-title", markup=False)
        yield OptionList(id="console-class", markup=False)
        yield Static("", id="console-message", markup=False)
        yield KeyBar()

    def on_mount(self) -> None:
        self.unicode = getattr(self.app, "unicode", False)
        follow_app(self)
        self.query_one("#console-queue", OptionList).focus()
        self.run_worker(self._poll, thread=True, group="console-poll", exit_on_error=False)

    def on_unmount(self) -> None:
        self._stop.set()
        self._wake.set()

    def set_unicode(self, unicode: bool) -> None:
        self.unicode = unicode
        if self.view is not None:
            self._show(self.view)

    def read_now(self) -> None:
        """Read the store again at once (after a sign-off or a decline)."""
        self._wake.set()

    # -- the reading thread --------------------------------------------------------------
    def _poll(self) -> None:
        while not self._stop.is_set():
            try:
                read = ClassRead(read_class(self.store, self.labs))
            except StoreUnavailable:
                read = ClassRead(None, "the course database cannot be reached: trying again")
            except Exception as exc:
                read = ClassRead(None, f"cannot read the class: {exc}")
            self.post_message(read)
            self._wake.wait(POLL_SECONDS)
            self._wake.clear()

    # -- on the event loop ---------------------------------------------------------------
    @on(ClassRead)
    def _read(self, message: ClassRead) -> None:
        if message.problem or self._problem_shown:
            self.query_one("#console-message", Static).update(message.problem)
            self._problem_shown = bool(message.problem)
        if message.view is not None:
            self.view = message.view
            self._show(message.view)
        for hook in self.on_shown:
            hook(message)

    def _show(self, view: ClassView) -> None:
        queue = self.query_one("#console-queue", OptionList)
        chosen = queue.highlighted_option.id if queue.highlighted_option is not None else None
        options = [
            Option(
                f"{n}. {e.pair[:24]:<24} {e.lab}/{e.exercise}  asked {e.requested_at[11:16]} UTC",
                id=f"q{e.id}",
            )
            for n, e in enumerate(view.queue, 1)
        ]
        queue.clear_options()
        queue.add_options(options)
        ids = [o.id for o in options]
        if options:
            queue.highlighted = ids.index(chosen) if chosen in ids else 0
        waiting = len(view.queue)
        self.query_one("#console-queue-title", Static).update(
            f"Sign-off queue: {waiting} waiting"
            + ("; enter opens the highlighted request" if waiting else " (nobody has asked)")
        )
        listing = self.query_one("#console-class", OptionList)
        top = listing.scroll_offset.y
        listing.clear_options()
        listing.add_options(
            [Option(row_text(r, self.unicode), id=f"s:{r.student}") for r in view.rows]
        )
        listing.scroll_to(y=top, animate=False)
        passed, failed = ("✓", "✗") if self.unicode else ("X", ".")
        self.query_one("#console-class-title", Static).update(
            f"Class: {len(view.rows)} at work; objectives {passed} passed, {failed} not yet"
            + (f"; console of {self.instructor}" if self.instructor else "")
        )

    def action_open_entry(self) -> None:
        queue = self.query_one("#console-queue", OptionList)
        option = queue.highlighted_option
        if self.view is None or option is None or option.id is None:
            self.query_one("#console-message", Static).update("no request to open")
            return
        entry = next((e for e in self.view.queue if f"q{e.id}" == option.id), None)
        if entry is None:
            return
        from .console_request import RequestScreen

        self.app.push_screen(RequestScreen(self.store, entry, self.labs), self._decided)

    @on(OptionList.OptionSelected, "#console-queue")
    def _selected(self, event: OptionList.OptionSelected) -> None:
        self.action_open_entry()

    def _decided(self, outcome: str | None) -> None:
        if outcome:
            self.query_one("#console-message", Static).update(outcome)
        self.read_now()
