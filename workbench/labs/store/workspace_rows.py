"""The students' workspace files in the store's ``workspace_files`` table (schema step 6).

One row per file of a student: its path inside the workspace (``runs/20260302-140509/run-1.jsonl``,
``mazes/my.txt``), the SHA-256 of its bytes, its size, its modification time, a revision that
grows by one with every change, and its bytes. A file removed stays as a row without content
(``deleted``) so that a server holding a copy removes it too; the oldest such rows are dropped
beyond :attr:`WorkspaceLimits.files` of them.

Every write checks the bounds (:class:`WorkspaceLimits`: a file's size, and the bytes and
number of a student's files together) inside its transaction, the student's writes queued
(PostgreSQL: an advisory lock per student; SQLite: its one writer), so writes racing for the
last of a quota cannot both pass. A path is checked by :func:`check_path` before it is used.
"""

from __future__ import annotations

import hashlib
from collections.abc import Callable
from dataclasses import dataclass
from datetime import datetime
from typing import Any

from .database import StoreError, Tx
from .rows import Rows, stamp_of

#: the key (first half) of the advisory lock that queues one student's workspace writes
WORKSPACE_LOCK = 0x5742
MIB = 1024 * 1024
#: the longest path inside a workspace, and the longest part of one, in bytes (UTF-8)
MAX_PATH_BYTES = 1024
MAX_PART_BYTES = 255
MAX_DEPTH = 16

Read = Callable[..., list[tuple[Any, ...]]]


class WorkspaceRefused(StoreError):
    """The store will not keep a file (too big, past the quota, a name it does not take);
    the message says which bound and what to do. Trying again gives the same answer."""


@dataclass(frozen=True)
class WorkspaceLimits:
    """How much one student's workspace may hold in the store."""

    #: the largest file, in bytes
    file_cap: int = 5 * MIB
    #: all of a student's files together, in bytes
    quota: int = 50 * MIB
    #: the most files a student may have
    files: int = 2000


LIMITS = WorkspaceLimits()


@dataclass(frozen=True)
class FileRow:
    """One file of a workspace as the store has it (without its bytes)."""

    path: str
    sha256: str
    size: int
    revision: int
    mtime: float
    deleted: bool = False


def sha256_hex(data: bytes) -> str:
    return hashlib.sha256(data).hexdigest()


def check_path(path: str) -> str:
    """``path`` when it names a file inside a workspace the store keeps: relative, parts
    separated by ``/``, none empty, ``.``, ``..`` or hidden (``.name``: the workbench's own
    files being written), no control characters, within the lengths above. Else
    :class:`WorkspaceRefused` saying what is wrong with it."""
    shown = repr(path[:80]) + ("..." if len(path) > 80 else "")
    if not path or not path.isprintable():
        raise WorkspaceRefused(f"{shown}: a file name must be printable text, not empty")
    if len(path.encode("utf-8", "surrogateescape")) > MAX_PATH_BYTES:
        raise WorkspaceRefused(f"{shown}: the path is longer than {MAX_PATH_BYTES} bytes")
    if path.startswith("/") or "\\" in path:
        raise WorkspaceRefused(f"{shown}: give a path inside the workspace, parts split by /")
    parts = path.split("/")
    if len(parts) > MAX_DEPTH:
        raise WorkspaceRefused(f"{shown}: more than {MAX_DEPTH} folders deep")
    for part in parts:
        if part in ("", ".", ".."):
            raise WorkspaceRefused(f"{shown}: an empty, '.' or '..' part is not a file name")
        if part.startswith("."):
            raise WorkspaceRefused(f"{shown}: hidden names (starting with '.') are not kept")
        if len(part.encode("utf-8", "surrogateescape")) > MAX_PART_BYTES:
            raise WorkspaceRefused(f"{shown}: a part is longer than {MAX_PART_BYTES} bytes")
    try:
        path.encode("utf-8")
    except UnicodeEncodeError:
        raise WorkspaceRefused(f"{shown}: the name is not UTF-8 text") from None
    return path


def _queue_student(tx: Tx, student: str) -> None:
    if tx.postgres:
        tx.execute("SELECT pg_advisory_xact_lock(?, hashtext(?))", (WORKSPACE_LOCK, student))


def _mib(size: int) -> str:
    return f"{size / MIB:.3g} MiB"


def put(
    tx: Tx,
    student: str,
    path: str,
    data: bytes,
    mtime: float,
    now: str,
    limits: WorkspaceLimits = LIMITS,
) -> FileRow:
    """Keep ``data`` as ``student``'s file ``path`` (a new revision when it changed); the
    bounds are checked first, and a file already stored with these bytes is left as it is."""
    check_path(path)
    size = len(data)
    if size > limits.file_cap:
        raise WorkspaceRefused(
            f"{path}: {_mib(size)} is more than the {_mib(limits.file_cap)} a file may take "
            "in the course store"
        )
    _queue_student(tx, student)
    sha = sha256_hex(data)
    old = tx.execute(
        "SELECT sha256, size, revision, mtime, deleted FROM workspace_files "
        "WHERE student = ? AND path = ?",
        (student, path),
    ).fetchone()
    if old is not None and not old[4] and str(old[0]) == sha:
        return FileRow(path, sha, int(old[1]), int(old[2]), float(old[3]))
    used, count = tx.execute(
        "SELECT COALESCE(SUM(size), 0), COUNT(*) FROM workspace_files "
        "WHERE student = ? AND deleted = 0 AND path <> ?",
        (student, path),
    ).fetchone()
    if int(count) + 1 > limits.files:
        raise WorkspaceRefused(
            f"{path}: the workspace already holds {int(count)} files, the most it may keep in "
            "the course store: remove some first"
        )
    if int(used) + size > limits.quota:
        raise WorkspaceRefused(
            f"{path}: the workspace would take {_mib(int(used) + size)}, more than its quota of "
            f"{_mib(limits.quota)} in the course store: remove some files first"
        )
    revision = int(old[2]) + 1 if old is not None else 1
    tx.execute(
        "INSERT INTO workspace_files (student, path, sha256, size, revision, mtime, deleted, "
        "content, updated_at) VALUES (?, ?, ?, ?, ?, ?, 0, ?, ?) "
        "ON CONFLICT (student, path) DO UPDATE SET sha256 = excluded.sha256, "
        "size = excluded.size, revision = excluded.revision, mtime = excluded.mtime, "
        "deleted = 0, content = excluded.content, updated_at = excluded.updated_at",
        (student, path, sha, size, revision, mtime, data, now),
    )
    return FileRow(path, sha, size, revision, mtime)


def remove(
    tx: Tx, student: str, path: str, now: str, limits: WorkspaceLimits = LIMITS
) -> FileRow | None:
    """Mark ``student``'s file ``path`` removed (a new revision, no content); None when the
    store does not hold it."""
    check_path(path)
    _queue_student(tx, student)
    old = tx.execute(
        "SELECT revision, mtime FROM workspace_files "
        "WHERE student = ? AND path = ? AND deleted = 0",
        (student, path),
    ).fetchone()
    if old is None:
        return None
    revision = int(old[0]) + 1
    tx.execute(
        "UPDATE workspace_files SET deleted = 1, content = NULL, size = 0, sha256 = '', "
        "revision = ?, updated_at = ? WHERE student = ? AND path = ?",
        (revision, now, student, path),
    )
    # the removals remembered are bounded too: the oldest beyond the file count go
    gone = tx.execute(
        "SELECT path FROM workspace_files WHERE student = ? AND deleted = 1 "
        "ORDER BY updated_at DESC, path LIMIT -1 OFFSET ?"
        if not tx.postgres
        else "SELECT path FROM workspace_files WHERE student = ? AND deleted = 1 "
        "ORDER BY updated_at DESC, path OFFSET ?",
        (student, limits.files),
    ).fetchall()
    for (old_path,) in gone:
        tx.execute(
            "DELETE FROM workspace_files WHERE student = ? AND path = ? AND deleted = 1",
            (student, old_path),
        )
    return FileRow(path, "", 0, revision, float(old[1]), deleted=True)


def index(read: Read, student: str) -> dict[str, FileRow]:
    """Every file of ``student`` the store knows, removed ones included, by path."""
    rows = read(
        "SELECT path, sha256, size, revision, mtime, deleted FROM workspace_files "
        "WHERE student = ? ORDER BY path",
        (student,),
    )
    return {
        str(p): FileRow(str(p), str(sha), int(size), int(rev), float(mtime), bool(deleted))
        for p, sha, size, rev, mtime, deleted in rows
    }


def content(read: Read, student: str, path: str) -> tuple[FileRow, bytes] | None:
    """A file's row and bytes; None when the store does not hold it (or it was removed)."""
    rows = read(
        "SELECT path, sha256, size, revision, mtime, content FROM workspace_files "
        "WHERE student = ? AND path = ? AND deleted = 0",
        (student, path),
    )
    if not rows:
        return None
    p, sha, size, rev, mtime, data = rows[0]
    return FileRow(str(p), str(sha), int(size), int(rev), float(mtime)), bytes(data or b"")


def by_digest(read: Read, sha256: str, students: tuple[str, ...]) -> list[tuple[str, str, bytes]]:
    """(student, path, bytes) of the files of ``students`` whose stored digest is ``sha256``
    (hex); the caller hashes the bytes again rather than trust the column."""
    if not students:
        return []
    marks = ", ".join("?" for _ in students)
    rows = read(
        "SELECT student, path, content FROM workspace_files "
        f"WHERE sha256 = ? AND deleted = 0 AND student IN ({marks}) ORDER BY student, path",
        (sha256, *students),
    )
    return [(str(s), str(p), bytes(c or b"")) for s, p, c in rows]


#: the largest run record a sign-off keeps a copy of (the default record cap is 20 MB)
EVIDENCE_CAP = 32 * MIB


def keep_evidence(tx: Tx, digest: str, data: bytes, now: str) -> None:
    """Keep ``data``, the run record a sign-off rests on, under its digest (``sha256:HEX``);
    a copy already kept stays as it is."""
    if f"sha256:{sha256_hex(data)}" != digest or len(data) > EVIDENCE_CAP:
        return
    tx.execute(
        "INSERT INTO signoff_evidence (digest, size, content, kept_at) VALUES (?, ?, ?, ?) "
        "ON CONFLICT (digest) DO NOTHING",
        (digest, len(data), data, now),
    )


def students(read: Read) -> list[str]:
    return [str(r[0]) for r in read("SELECT DISTINCT student FROM workspace_files ORDER BY 1")]


def record_place(run_record: str, people: tuple[str, ...]) -> tuple[str, str] | None:
    """(student, path) of a run record kept in a served student's workspace
    (``.../workspaces/<student>/runs/...``), when it is one of ``people``'s."""
    parts = run_record.replace("\\", "/").split("/")
    for i in range(len(parts) - 2, 0, -1):
        if parts[i - 1] == "workspaces" and parts[i] in people:
            return parts[i], "/".join(parts[i + 1 :])
    return None


def evidence_copies(
    read: Read, run_record: str, digest: str, people: tuple[str, ...]
) -> list[tuple[str, str, bytes]]:
    """The copies in the store of a sign-off's run record, as (student, path, bytes): the
    files of ``people`` (the pair) stored with its digest (``sha256:HEX``), the copy kept
    when it was signed (student and path empty), and the file at the record's own place in
    the workspace whatever it holds now. The caller hashes each copy's bytes."""
    people = tuple(p for p in people if p)
    hexdigest = digest.removeprefix("sha256:")
    found = by_digest(read, hexdigest, people) if hexdigest else []
    if hexdigest:
        kept = read("SELECT content FROM signoff_evidence WHERE digest = ?", (digest,))
        found += [("", "", bytes(row[0] or b"")) for row in kept]
    place = record_place(run_record, people)
    if place is not None and not any((s, p) == place for s, p, _ in found):
        got = content(read, *place)
        if got is not None:
            found.append((place[0], place[1], got[1]))
    return found


class WorkspaceRows:
    """The students' workspace files over the store's connection (see
    :mod:`.workspace_sync`). Writes need the database
    (:class:`~workbench.labs.store.database.StoreUnavailable` while it is away)."""

    def __init__(self, rows: Rows) -> None:
        self.rows = rows

    def put(
        self,
        student: str,
        path: str,
        data: bytes,
        mtime: float,
        limits: WorkspaceLimits = LIMITS,
        now: datetime | None = None,
    ) -> FileRow:
        """Keep ``data`` as ``student``'s workspace file ``path`` within ``limits``;
        :class:`WorkspaceRefused` says which bound it would pass."""
        with self.rows.write() as tx:
            return put(tx, student, path, data, mtime, stamp_of(now), limits)

    def remove(self, student: str, path: str, now: datetime | None = None) -> FileRow | None:
        """Mark ``student``'s workspace file ``path`` removed; None when it was not kept."""
        with self.rows.write() as tx:
            return remove(tx, student, path, stamp_of(now))

    def index(self, student: str) -> dict[str, FileRow]:
        """The workspace files the store holds for ``student`` (removed ones too), by path."""
        return index(self.rows.read, student)

    def file(self, student: str, path: str) -> tuple[FileRow, bytes] | None:
        """One workspace file's row and bytes; None when the store does not hold it."""
        return content(self.rows.read, student, path)

    def by_digest(self, sha256: str, students: tuple[str, ...]) -> list[tuple[str, str, bytes]]:
        """The files of ``students`` stored with the digest ``sha256`` (hex)."""
        return by_digest(self.rows.read, sha256, students)
