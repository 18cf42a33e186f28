"""The instructor's console: the class live from the store, and the sign-off queue.

At the top, the requests for sign-off in the order the students asked; below, every student
with the exercise they have open (its id whole, on a line of its own where the columns do not
fit), its objectives (✓/✗, ``X``/``.`` in ASCII mode) and their place in the queue, and a
line of marks where the evidence mixes programs or shares a program with another student's.
``g`` opens the grid of students by exercises (:mod:`.console_grid`). A thread of the
screen's own reads the store about once a second (:func:`workbench.labs.classview.read_class`),
never the event loop: a course database may be across the network. Enter on a request opens
it (:mod:`.console_request`), where the instructor signs it off with their own key, typed in
their own session, or declines it with a note.
"""

from __future__ import annotations

import threading
import time
from collections.abc import Callable, Sequence
from typing import Any, ClassVar

from textual import on
from textual.app import ComposeResult
from textual.binding import BindingType
from textual.message import Message
from textual.screen import Screen
from textual.widgets import OptionList, Static
from textual.widgets.option_list import Option

from workbench.labs.classview import ClassView, StudentRow, read_class
from workbench.labs.course_store import ChangeWaiter, QueueEntry, Store, StoreUnavailable
from workbench.labs.model import Lab

from ..host import FollowsUnicode
from ..keys import bindings
from ..plain import follow_app
from ..widgets.key_bar import KeyBar

#: seconds between reads of the store
#: while the store is away, how often the console tries to read it again (seconds)
AWAY_SECONDS = 1.0


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


def _state(row: StudentRow) -> str:
    if row.signed:
        return "signed off"
    if row.waiting is not None:
        return f"waiting #{row.waiting}"
    if row.problem:
        return "unreadable"
    return ""


def _flags(row: StudentRow) -> str:
    """What the instructor should look at: evidence on several programs, a shared program."""
    flags = []
    if row.mixed:
        flags.append(f"evidence mixes {len(row.mixed)} programs")
    if row.same_program_as:
        flags.append(f"same program as {', '.join(row.same_program_as)}")
    return "; ".join(flags)


def class_prompts(rows: Sequence[StudentRow], unicode: bool, width: int) -> list[str]:
    """Each student's entry in the class list: who, the exercise (whole: never cut), the
    objectives, the queue; on one line in columns where they fit ``width``, else the
    exercise on a line of its own; and a line of flags (mixed programs, copy hints)."""
    who = [r.student + (f"+{r.partner}" if r.partner else "") for r in rows]
    where = [f"{r.lab}/{r.exercise}" for r in rows]
    marks = [objective_marks(r, unicode) for r in rows]
    states = [_state(r) for r in rows]
    widths = [max(map(len, column), default=0) for column in (who, where, marks, states)]
    one_line = sum(widths) + 3 <= width
    prompts = []
    for row, w, x, m, st in zip(rows, who, where, marks, states, strict=True):
        if one_line:
            text = f"{w:<{widths[0]}} {x:<{widths[1]}} {m:<{widths[2]}} {st}".rstrip()
        else:
            text = f"{w:<{widths[0]}} {m:<{widths[2]}} {st}".rstrip() + f"\n  {x}"
        flags = _flags(row)
        prompts.append(text + (f"\n  ! {flags}" if flags else ""))
    return prompts


def queue_prompt(n: int, entry: QueueEntry, width: int) -> str:
    """One request of the queue: its place, the pair, the exercise (whole) and when asked."""
    first = f"{n}. {entry.pair}"
    rest = f"{entry.lab}/{entry.exercise}  asked {entry.requested_at[11:16]}"
    if len(first) + 2 + len(rest) <= width:
        return f"{first:<{width - len(rest) - 1}} {rest}"
    return f"{first}\n   {rest}"


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

    BINDINGS: ClassVar[list[BindingType]] = [*bindings("console.open", "console.grid")]

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
        #: called with each read, once shown (the bench measures with it; the grid follows it)
        self.on_shown: list[Callable[[Any], None]] = []

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
        """Read the class, then again at word of a change to the store (another connection's
        commit: a student's progress or request), at ``read_now``, or after a while anyway."""
        waiter = ChangeWaiter(self.store.watch_changes, self._wake, self._stop, away=AWAY_SECONDS)
        try:
            while not self._stop.is_set():
                try:
                    read = ClassRead(read_class(self.store, self.labs))
                except StoreUnavailable:
                    read = ClassRead(None, "the course database cannot be reached: trying again")
                except Exception as exc:
                    read = ClassRead(None, f"cannot read the class: {exc}")
                self.post_message(read)
                waiter.wait()
        finally:
            waiter.close()

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
        width = self._room(queue)
        options = [
            Option(queue_prompt(n, e, width), id=f"q{e.id}") for n, e in enumerate(view.queue, 1)
        ]
        queue.clear_options()
        queue.add_options(options)
        ids = [o.id for o in options]
        if options:
            queue.highlighted = ids.index(chosen) if chosen in ids else 0
        waiting = len(view.queue)
        self.query_one("#console-queue-title", Static).update(
            f"Sign-off queue: {waiting} waiting"
            + ("; times UTC; enter opens one" if waiting else " (nobody has asked)")
        )
        listing = self.query_one("#console-class", OptionList)
        top = listing.scroll_offset.y
        listing.clear_options()
        prompts = class_prompts(view.rows, self.unicode, self._room(listing))
        listing.add_options(
            [Option(p, id=f"s:{r.student}") for r, p in zip(view.rows, prompts, strict=True)]
        )
        listing.scroll_to(y=top, animate=False)
        passed, failed = ("✓", "✗") if self.unicode else ("X", ".")
        self.query_one("#console-class-title", Static).update(
            f"Class: {len(view.rows)} at work; objectives {passed} passed, {failed} not yet"
            + (f"; console of {self.instructor}" if self.instructor else "")
        )

    def _room(self, listing: OptionList) -> int:
        """The columns an option of ``listing`` has (inside its frame and scroll bar)."""
        scrollbar = listing.styles.scrollbar_size_vertical
        if listing.size.width:  # the content's width: inside the frame
            return max(20, listing.size.width - scrollbar)
        return max(20, self.app.size.width - listing.styles.gutter.width - scrollbar)

    def on_resize(self) -> None:
        if self.view is not None:
            self._show(self.view)

    def action_grid(self) -> None:
        """The students by exercises grid, read with the class."""
        from .console_grid import GridScreen

        self.app.push_screen(GridScreen(self))

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

        hints = self.view.hints
        self.app.push_screen(RequestScreen(self.store, entry, self.labs, hints), self._decided)

    @on(OptionList.OptionSelected, "#console-queue")
    def _selected(self, event: OptionList.OptionSelected) -> None:
        self.action_open_entry()

    def _decided(self, outcome: str | None) -> None:
        if outcome:
            self.query_one("#console-message", Static).update(outcome)
        self.read_now()
