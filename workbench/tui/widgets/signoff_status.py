"""Where a student's request for sign-off stands, on their labs screen, kept up from the store.

The widget follows one exercise of one student (:meth:`SignoffStatus.follow`). A thread of its
own reads the store about once a second (the store may be a course database across the network,
so never on the event loop): the request's place in the sign-off queue, an instructor's decline
with its note, and a sign-off made at the instructor's console. It shows that in one or two
lines and posts :class:`SignoffStatus.Signed` when a new sign-off of the exercise appears.
:meth:`SignoffStatus.ask` puts the exercise in the queue (also from that thread).
"""

from __future__ import annotations

import threading
from dataclasses import dataclass

from textual.message import Message
from textual.widgets import Static

from workbench.labs.course_store import (
    DECLINED,
    SIGNED,
    WAITING,
    WITHDRAWN,
    ChangeWaiter,
    QueueState,
    Store,
    StoreUnavailable,
)

#: how often a SQLite store's data version is asked (seconds): a student's status may take
#: this long to show a sign-off; PostgreSQL's word comes at once
CHECK_SECONDS = 0.25
#: while the store is away, how often the status tries to read it again (seconds)
AWAY_SECONDS = 1.0


@dataclass(frozen=True)
class Target:
    student: str
    partner: str
    driver: str
    lab: str
    exercise: str


@dataclass(frozen=True)
class Seen:
    """What one read of the store found for the followed exercise."""

    target: Target
    queue: QueueState | None
    #: (instructor, signed_at) of the exercise's last sign-off, if any
    signed: tuple[str, str] | None
    problem: str = ""


def ordinal(n: int) -> str:
    """1st, 2nd, 3rd, 4th, 11th, 21st ..."""
    suffix = "th" if 10 <= n % 100 <= 20 else {1: "st", 2: "nd", 3: "rd"}.get(n % 10, "th")
    return f"{n}{suffix}"


def words(seen: Seen, ready_key: str) -> str:
    """What the student reads about their request."""
    if seen.problem:
        return seen.problem
    entry = seen.queue.entry if seen.queue is not None else None
    if entry is not None and entry.state == WAITING and seen.queue is not None:
        place = seen.queue.place or 1
        return (
            f"waiting for sign-off: {ordinal(place)} in the queue "
            f"({seen.queue.waiting} waiting); {ready_key} again keeps your place"
        )
    if entry is not None and entry.state == DECLINED:
        return (
            f"sign-off declined by {entry.instructor}: {entry.note}\n"
            f"fix it, then press {ready_key} to ask again"
        )
    if seen.signed is not None or (entry is not None and entry.state == SIGNED):
        return ""  # the exercise's title says who signed it off
    if entry is not None and entry.state == WITHDRAWN:
        return f"request withdrawn; press {ready_key} to ask for sign-off"
    return ""


class SignoffStatus(Static):
    """One exercise's request for sign-off, as the store has it."""

    DEFAULT_CSS = """
    SignoffStatus {
        height: auto;
        max-height: 3;
        padding: 0 1;
        color: $text-accent;
    }
    """

    class Signed(Message):
        """A sign-off of the followed exercise appeared in the store."""

        def __init__(self, lab: str, exercise: str, instructor: str, signed_at: str) -> None:
            super().__init__()
            self.lab = lab
            self.exercise = exercise
            self.instructor = instructor
            self.signed_at = signed_at

    class Asked(Message):
        """The outcome of :meth:`SignoffStatus.ask`: the request's state, or why it failed."""

        def __init__(self, state: QueueState | None, problem: str = "") -> None:
            super().__init__()
            self.state = state
            self.problem = problem

    def __init__(self, store: Store | None, ready_key: str = "r", **kw: object) -> None:
        super().__init__("", markup=False, **kw)  # type: ignore[arg-type]
        self.store = store
        self.ready_key = ready_key
        self._target: Target | None = None
        self._asks: list[Target] = []
        self._wake = threading.Event()
        self._stop = threading.Event()
        self._lock = threading.Lock()
        #: the last sign-off seen, by (lab, exercise): a newer one is news
        self._known: dict[tuple[str, str], tuple[str, str] | None] = {}
        self.seen: Seen | None = None
        #: the reading thread starts once the widget is mounted and has a store, and only once
        self._mounted_once = False
        self._polling = False

    def on_mount(self) -> None:
        self.display = False
        self._mounted_once = True
        self._start()

    def use(self, store: Store) -> None:
        """Read ``store`` from now on (one opened after the widget was made)."""
        if self.store is None:
            self.store = store
            self._start()

    def _start(self) -> None:
        if self.store is not None and self._mounted_once and not self._polling:
            self._polling = True
            self.run_worker(self._poll, thread=True, group="signoff-status", exit_on_error=False)

    def on_unmount(self) -> None:
        self._stop.set()
        self._wake.set()

    def follow(self, student: str, partner: str, driver: str, lab: str, exercise: str) -> None:
        """Follow this exercise from now on (read at once)."""
        with self._lock:
            self._target = Target(student, partner, driver, lab, exercise)
        self._show("")
        self._wake.set()

    def ask(self) -> None:
        """Ask for sign-off of the followed exercise (in the reading thread)."""
        with self._lock:
            if self._target is not None:
                self._asks.append(self._target)
        self._wake.set()

    # -- the reading thread ------------------------------------------------------------------
    def _poll(self) -> None:
        """Ask and read in this thread: again at word of a change to the store (an instructor
        signed or declined), when asked to at once, or after a while anyway."""
        store = self.store
        assert store is not None
        waiter = ChangeWaiter(
            store.watch_changes, self._wake, self._stop, check=CHECK_SECONDS, away=AWAY_SECONDS
        )
        try:
            while not self._stop.is_set():
                with self._lock:
                    target, asks, self._asks = self._target, self._asks, []
                for asked in asks:
                    self._request(store, asked)
                if target is not None:
                    seen = self._read(store, target)
                    try:
                        self.app.call_from_thread(self._take, seen)
                    except RuntimeError:  # the app is ending
                        return
                waiter.wait()
        finally:
            waiter.close()

    def _request(self, store: Store, target: Target) -> None:
        try:
            asked = self.Asked(
                store.queue.request(
                    target.student, target.partner, target.driver, target.lab, target.exercise
                )
            )
        except StoreUnavailable:
            problem = "the course database cannot be reached: ask again when it is back"
            asked = self.Asked(None, problem)
        except Exception as exc:
            asked = self.Asked(None, f"not asked: {exc}")
        self.post_message(asked)  # thread-safe

    def _read(self, store: Store, target: Target) -> Seen:
        if store.offline:  # the saving side is waiting for the database: no reads meanwhile
            return Seen(target, None, None, "the course database cannot be reached")
        try:
            state = store.queue.state(target.student, target.lab, target.exercise)
            rows = [
                r
                for r in store.signoffs.of(student=target.student, lab=target.lab)
                if r.exercise == target.exercise
            ]
        except StoreUnavailable:
            return Seen(target, None, None, "the course database cannot be reached")
        except Exception as exc:
            return Seen(target, None, None, f"cannot read the sign-off queue: {exc}")
        signed = (rows[-1].instructor, rows[-1].signed_at) if rows else None
        return Seen(target, state, signed)

    # -- on the event loop -----------------------------------------------------------------
    def _take(self, seen: Seen) -> None:
        with self._lock:
            if seen.target != self._target:
                return  # read for an exercise no longer shown
        key = (seen.target.lab, seen.target.exercise)
        if not seen.problem:
            before = self._known.get(key)
            self._known[key] = seen.signed
            if seen.signed is not None and seen.signed != before:
                self.post_message(self.Signed(*key, *seen.signed))
        self.seen = seen
        self._show(words(seen, self.ready_key))

    def _show(self, text: str) -> None:
        self.update(text)
        self.display = bool(text)
