"""What the store's repositories share: the one connection they work through (:class:`Rows`,
which :class:`~workbench.labs.store.store.Store` is) and how they write a moment.

Each repository is a small class over one idea's tables: the students' work
(:mod:`.progress_rows`), the sign-off log, lockouts and events (:mod:`.signoff_rows`), the
sign-off queue (:mod:`.queue`), the workspace files (:mod:`.workspace_rows`) and, in a course
database, the instructors' roster and keys (:mod:`.instructor_rows`). They hold no state of
their own: every read and write goes through the store's connection, its lock, its deadline
and (for the writes kept while a course database is away) its pending writes.
"""

from __future__ import annotations

from contextlib import AbstractContextManager
from datetime import UTC, datetime
from typing import Any, Protocol

from .database import Tx
from .pending import PendingWrite


class Rows(Protocol):
    """The store's connection as a repository uses it."""

    #: where the store is, as messages name it (a file, or the database's address)
    where: str

    @property
    def postgres(self) -> bool: ...

    def read(self, sql: str, params: tuple[Any, ...] = ()) -> list[tuple[Any, ...]]:
        """The rows of one query."""
        ...

    def write(self) -> AbstractContextManager[Tx]:
        """One write transaction."""
        ...

    def keep(self, write: PendingWrite) -> bool:
        """Write one upsert, or keep it until the database answers; True when written."""
        ...

    def waiting(self) -> list[PendingWrite]:
        """The writes kept until the database answers, oldest first."""
        ...


def utc_iso(moment: datetime) -> str:
    """A moment as UTC ISO 8601 to the second, e.g. ``2026-02-03T14:05:09Z``."""
    if moment.tzinfo is None:
        raise ValueError("times must carry a time zone")
    return moment.astimezone(UTC).isoformat(timespec="seconds").replace("+00:00", "Z")


def stamp_of(now: datetime | None) -> str:
    """``now`` (else the present moment) as :func:`utc_iso` writes it."""
    return utc_iso(now or datetime.now(UTC))
