"""The course store's life beside a front end: opened off the front end's thread, written in
the background, tried again while the course database is away, and given a last try at the
end. A front end subscribes to what happens (:data:`StoreEvent`) and only says it.

The app makes one :class:`CourseStore` from its settings. :meth:`CourseStore.open_for` opens
the store (SQLite in the data folder, or the course's PostgreSQL database, which may hang
until its deadline) in a thread and publishes :class:`Opened` with the pair's names as the
store spells them. While the database is away every save is kept pending (in a file too, for
a later app) and one thread of the service tries it again every :data:`RETRY_SECONDS`, one
try at a time; it publishes :class:`Away` when a save could not be written and :class:`Back`
once everything kept is. A save the database refused is :class:`SaveRefused`. The changes an
earlier app kept (:meth:`CourseStore.save_kept`) end in :class:`KeptSaved` or
:class:`KeptNotSaved`.

It is also the front ends' one door to the store's values (the store, its errors, the sign-off
queue's entries and states), so no front end reaches into the store's modules.

Listeners are called from the service's threads (and the store's writing thread), or from the
caller's thread for what a caller reports; a front end hands each event to its own event loop.
Nothing here imports a user interface.
"""

from __future__ import annotations

import contextlib
import logging
import os
import threading
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from .store.changes import ChangeWaiter
from .store.pending import pending_path
from .store.queue import DECLINED, SIGNED, WAITING, WITHDRAWN, QueueEntry, QueueState
from .store.store import Store, StoreError, StoreUnavailable, resolve_data_dir
from .store.workspace_sync import WorkspacePusher

__all__ = [
    "DECLINED",
    "SIGNED",
    "WAITING",
    "WITHDRAWN",
    "Away",
    "Back",
    "ChangeWaiter",
    "CourseStore",
    "KeptNotSaved",
    "KeptSaved",
    "Opened",
    "QueueEntry",
    "QueueState",
    "SaveRefused",
    "Store",
    "StoreError",
    "StoreEvent",
    "StoreUnavailable",
    "WorkspacePusher",
    "open_to_read",
    "resolve_data_dir",
]

log = logging.getLogger(__name__)

#: seconds between tries to write what the course database did not get
RETRY_SECONDS = 2.0


@dataclass(frozen=True)
class Opened:
    """The store is open (``store`` None when it could not be: ``problem`` says why), and the
    pair's names as the store spells them."""

    store: Store | None
    problem: str
    student: str
    partner: str


@dataclass(frozen=True)
class Away:
    """A save could not reach the course database: ``pending`` changes are kept here and
    written once it is back."""

    pending: int


@dataclass(frozen=True)
class Back:
    """Everything kept while the course database was away is written."""


@dataclass(frozen=True)
class SaveRefused:
    """The store refused a save (it was not kept: it would fail again)."""

    error: StoreError


@dataclass(frozen=True)
class KeptSaved:
    """The changes an earlier app kept while the course database was away are written."""


@dataclass(frozen=True)
class KeptNotSaved:
    """The changes an earlier app kept could not be written (``error`` says why)."""

    error: Exception


StoreEvent = Opened | Away | Back | SaveRefused | KeptSaved | KeptNotSaved
Listener = Callable[[StoreEvent], None]


class CourseStore:
    """The one store of an app: the data folder's SQLite file, or the course database ``db``,
    for ``student``. Opened once (:meth:`open`), from whichever thread asks first."""

    def __init__(self, data_dir: str | os.PathLike | None, db: str | None, student: str) -> None:
        self.data_dir = data_dir
        self.db = db
        self.student = student
        #: the open store (None until opened, or when it could not be)
        self.store: Store | None = None
        #: why the store could not be opened ("" when it was, or is not yet)
        self.problem = ""
        self._opened = False
        self._open_lock = threading.Lock()
        self._listeners: list[Listener] = []
        self._lock = threading.Lock()
        #: the retrying thread runs (one at a time), and whether it should publish Back
        self._retrying = False
        self._told_away = False
        self._ending = threading.Event()

    # -- listeners -----------------------------------------------------------------------------
    def subscribe(self, listener: Listener) -> None:
        """Call ``listener`` with every event from now on (from any thread)."""
        self._listeners.append(listener)

    def _publish(self, event: StoreEvent) -> None:
        for listener in list(self._listeners):
            try:
                listener(event)
            except Exception:  # whoever listens is gone (the app ending): the work is kept
                log.debug("a store event was not taken", exc_info=True)

    # -- opening -------------------------------------------------------------------------------
    @property
    def pending_file(self) -> Path:
        """Where the student's writes wait for the course database, beyond this app."""
        return pending_path(resolve_data_dir(self.data_dir), self.student)

    def open(self) -> Store | None:
        """The store, opened the first time it is asked for (waits for a course database up
        to its deadline: call it off an event loop). A course database that is down gives a
        store that keeps the work until it is back; one that cannot be opened at all gives
        None, and :attr:`problem` says why."""
        with self._open_lock:
            if not self._opened:
                self._opened = True
                self._open_once()
            return self.store

    def _open_once(self) -> None:
        try:
            store = Store.open(self.data_dir, db=self.db, offline_ok=True)
        except Exception as exc:  # the labs work without saving rather than not at all
            where = "the course database" if self.db else "the data folder"
            self.problem = f"cannot open {where}, so nothing is saved: {exc}"
            return
        if self.db:
            # what waits for the database is kept in a file too: it outlives this app
            for problem in store.keep_pending_in(self.pending_file, self.student):
                log.warning("%s", problem)
            # and a save never waits for it: a database that hangs must not freeze a screen
            store.write_in_background(self._trouble)
        self.store = store

    def open_for(self, student: str, partner: str, *, respell: bool = True) -> None:
        """Open the store in a thread, then publish :class:`Opened` with the pair as the store
        spells them when ``respell`` (so "alice doe" resumes Alice Doe's progress)."""
        self.student = student

        def run() -> None:
            store = self.open()
            names = (student, partner)
            if store is not None and respell:
                with contextlib.suppress(Exception):  # away: the names stay as typed
                    names = (store.progress.spelling(student),
                             store.progress.spelling(partner) if partner else "")  # fmt: skip
            self._publish(Opened(store, self.problem, *names))

        self._thread(run, "store-open")

    @staticmethod
    def _thread(run: Callable[[], None], name: str) -> None:
        threading.Thread(target=run, name=name, daemon=True).start()

    # -- away and back -------------------------------------------------------------------------
    def kept(self) -> None:
        """A save was kept pending (its call returned False): the course database is away.
        Said with :class:`Away` when changes wait; they are tried again until written."""
        store = self.store
        if store is None:
            return
        if store.pending:
            self._told_away = True
            self._publish(Away(store.pending))
        self._retry()

    def read_away(self) -> None:
        """What a front end read could not reach the database (it says so itself):
        :class:`Back` follows once the database answers again (the front end reads again
        then)."""
        self._told_away = True
        self._retry()

    def _trouble(self, error: StoreError) -> None:
        """A save failed in the store's writing thread."""
        if isinstance(error, StoreUnavailable):
            self.kept()
        else:
            self._publish(SaveRefused(error))

    def _retry(self) -> None:
        """Try what is kept again every RETRY_SECONDS, in one thread, until it is written."""
        with self._lock:
            if self._retrying or self.store is None:
                return
            self._retrying = True
        self._thread(self._retry_until_written, "store-retry")

    def _retry_until_written(self) -> None:
        store = self.store
        assert store is not None
        while not self._ending.wait(RETRY_SECONDS):
            try:
                done = _flush(store)
            except StoreUnavailable:
                continue
            except StoreError as exc:
                self._publish(SaveRefused(exc))
                done = True
            except Exception:  # the store closed under the try (the app ending)
                break
            if done:
                break
        with self._lock:
            self._retrying = False
            told, self._told_away = self._told_away, False
        if told and not self._ending.is_set():  # (a save merely on its way is no news)
            self._publish(Back())

    def retry_if_pending(self) -> None:
        """Try again what waits (a save on its way as a front end comes up)."""
        if self.store is not None and self.store.pending:
            self._retry()

    # -- what an earlier app kept --------------------------------------------------------------
    def save_kept(self) -> None:
        """Write the changes an earlier app kept in the pending file (with a course database),
        in a thread, one try at a time until they are written; then say so."""
        if not self.db or not self.pending_file.is_file():
            return

        def run() -> None:
            store = self.open()
            if store is None:
                return
            while store.pending and not self._ending.is_set():
                try:
                    done = _flush(store)
                except Exception as exc:  # written by no retry: say why, work goes on
                    self._publish(KeptNotSaved(exc))
                    return
                if done:
                    self._publish(KeptSaved())
                    return
                self._ending.wait(RETRY_SECONDS)

        self._thread(run, "store-kept")

    # -- the workspace -------------------------------------------------------------------------
    def workspace_pusher(
        self, workspace: Path, tell: Callable[[str], None]
    ) -> WorkspacePusher | None:
        """With a course database, a pusher that sends each file saved in ``workspace`` to it,
        over a store of its own (started here); None without one."""
        db = self.db
        if not db:
            return None
        data_dir = self.data_dir

        def open_store() -> Store:
            return Store.open(data_dir, db=db, offline_ok=True)

        pusher = WorkspacePusher(open_store, self.student, workspace, tell)
        pusher.start()
        return pusher

    # -- the end -------------------------------------------------------------------------------
    def finish(self, seconds: float) -> None:
        """A last try, for at most ``seconds``, to write what the database did not get yet
        (while it is away the writes are in their file already, for the next app), then the
        store closed. Waits: call it off an event loop."""
        self._ending.set()
        store = self.store
        if store is None:
            return
        if store.in_background:
            store.keep_pending_now()  # a write on its way when the database hangs
            if not store.offline:
                with contextlib.suppress(Exception):
                    store.flush_soon().result(timeout=seconds)
        elif not store.offline:
            with contextlib.suppress(Exception):
                store.flush()
        store.close()


def open_to_read(data_dir: str | os.PathLike | None, db: str | None) -> Store:
    """The store a front end that only reads the class and signs (the instructor's console)
    opens at its start: :class:`StoreError` when it cannot be opened, whose words say why."""
    return Store.open(data_dir, db=db)


def _flush(store: Store) -> bool:
    """One try to write what is pending: in the store's own writing thread when it has one
    (one write at a time), else here."""
    if store.in_background:
        return store.flush_soon().result()
    return store.flush()
