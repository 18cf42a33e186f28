"""Moving a data folder's SQLite store into a course's PostgreSQL database, checked after.

Everything moves: the sign-off log (each record with its id, sequence number and hashes, so
the log's head stays the same), progress, places, drivers, lockouts, the failed-attempt log,
and the instructors of the data folder's roster with their encrypted key files; and the
served students' workspaces (``<data-dir>/workspaces/<user>``: their files and run records),
which a course database keeps itself. The target must hold none of these yet; the copy is one
transaction, so a failure leaves it as it was. A workspace file the course database does not
take (past its bounds, a name it refuses) stays in the data folder only, and is named.
Afterwards both stores are read again and compared: the number of rows of every table, every
sign-off record, the log's head, the roster and every workspace file's digest.
"""

from __future__ import annotations

import os
from dataclasses import dataclass, field
from datetime import UTC, datetime
from pathlib import Path

from workbench.files.workspace import workspace_folder

from .signlog import Head
from .signoff.roster import roster_keys
from .signoff.verify import log_head
from .store import workspace_rows
from .store.store import SIGNOFF_COLUMNS, Store, StoreError, utc_iso
from .store.workspace_rows import WorkspaceRefused
from .store.workspace_sync import local_files, read_local

TABLES: dict[str, tuple[str, ...]] = {
    "signoffs": SIGNOFF_COLUMNS,
    "progress": ("student", "lab", "exercise", "progress", "updated_at"),
    "places": ("student", "lab", "exercise", "updated_at"),
    "drivers": ("student", "partner", "lab", "exercise", "driver", "updated_at"),
    "lockouts": ("instructor", "failures", "locked_until", "updated_at"),
    "events": ("id", "at", "instructor", "event", "detail"),
}
#: the tables whose ids are kept, and so whose id sequence must move on past them
IDENTITY = ("signoffs", "events")


@dataclass(frozen=True)
class CopyReport:
    counts: dict[str, int]
    instructors: int
    head: Head
    #: workspace files copied, by student, and those left in the data folder (with why)
    workspaces: dict[str, int] = field(default_factory=dict)
    left: tuple[str, ...] = ()


def workspaces(data_dir: Path) -> dict[str, Path]:
    """The served students' workspace folders in a data folder, by login name."""
    base = Path(data_dir) / "workspaces"
    found: dict[str, Path] = {}
    try:
        entries = sorted(os.scandir(base), key=lambda e: e.name)
    except (FileNotFoundError, NotADirectoryError):
        return found
    for entry in entries:
        try:
            folder = workspace_folder(data_dir, entry.name)
        except ValueError:
            continue  # not a login name (the sync state's folder among them)
        if entry.is_dir(follow_symlinks=False):
            found[entry.name] = folder
    return found


def _workspace_files(
    data_dir: Path,
) -> tuple[dict[str, dict[str, tuple[bytes, float]]], list[str]]:
    """Every workspace file the copy takes (bytes and modification time, by student and
    path), and what it leaves (with why)."""
    out: dict[str, dict[str, tuple[bytes, float]]] = {}
    left: list[str] = []
    cap = workspace_rows.LIMITS.file_cap
    for user, folder in workspaces(data_dir).items():
        found, problems = local_files(folder)
        left += [f"{user}: {p}" for p in problems]
        files = out.setdefault(user, {})
        for rel in found:
            try:
                got = read_local(folder / rel, cap)
            except WorkspaceRefused as exc:
                left.append(f"{user}: {rel}: {exc}")
                continue
            if got is not None:
                files[rel] = (got[0], got[1].st_mtime)
    return out, left


def counts(store: Store) -> dict[str, int]:
    out = {table: int(store.read(f"SELECT count(*) FROM {table}")[0][0]) for table in TABLES}
    if store.instructors is not None:
        out["instructors"] = store.instructors.count()
    return out


def copy_store(source: Store, target: Store) -> CopyReport:
    """Copy the SQLite ``source`` into the empty PostgreSQL ``target``, then check the copy;
    :class:`StoreError` says what is in the way or what differs."""
    if source.postgres or not target.postgres:
        raise StoreError("the copy goes from a data folder's SQLite store to PostgreSQL")
    already = {t: n for t, n in counts(target).items() if n}
    if already:
        held = ", ".join(f"{n} {t}" for t, n in already.items())
        raise StoreError(
            f"{target.where} already holds {held}: move a data folder into an empty database "
            "(or one made for it with CREATE DATABASE)"
        )
    offered = roster_keys(source)  # the data folder's files
    roster = offered.entries()
    keys = {name: offered.key_text(name)[0] for name in roster}
    stored_files = int(target.read("SELECT count(*) FROM workspace_files")[0][0])
    if stored_files:
        raise StoreError(
            f"{target.where} already holds {stored_files} workspace file(s): move a data "
            "folder into an empty database (or one made for it with CREATE DATABASE)"
        )
    rows = {t: source.read(f"SELECT {', '.join(c)} FROM {t}") for t, c in TABLES.items()}
    files, left = _workspace_files(source.data_dir)
    copied: dict[str, dict[str, str]] = {}
    stamp = utc_iso(datetime.now(UTC))
    with target.write() as tx:
        for table, columns in TABLES.items():
            sql = (
                f"INSERT INTO {table} ({', '.join(columns)}) "
                f"VALUES ({', '.join('?' for _ in columns)})"
            )
            for row in rows[table]:
                tx.execute(sql, row)
        for table in IDENTITY:
            tx.execute(
                f"SELECT setval(pg_get_serial_sequence('{table}', 'id'), "
                f"(SELECT COALESCE(max(id), 0) + 1 FROM {table}), false)"
            )
        for entry in roster.values():
            tx.execute(
                "INSERT INTO instructors (name, public_key, added, key_file) VALUES (?, ?, ?, ?)",
                (entry.name, entry.public_key, entry.added, keys[entry.name]),
            )
        for user, kept in files.items():
            for rel, (data, mtime) in kept.items():
                try:
                    put = workspace_rows.put(tx, user, rel, data, mtime, stamp)
                except WorkspaceRefused as exc:
                    left.append(f"{user}: {exc}")
                    continue
                copied.setdefault(user, {})[rel] = put.sha256
    report = check_copy(source, target, len(roster))
    check_workspaces(target, copied)
    return CopyReport(
        report.counts,
        report.instructors,
        report.head,
        {user: len(done) for user, done in copied.items()},
        tuple(left),
    )


def check_workspaces(target: Store, copied: dict[str, dict[str, str]]) -> None:
    """Compare the workspace files in ``target`` with those copied (digests by student and
    path); :class:`StoreError` names the first difference."""
    for user, shas in copied.items():
        stored = {
            path: row.sha256
            for path, row in target.workspaces.index(user).items()
            if not row.deleted
        }
        if stored != shas:
            first = sorted(set(stored.items()) ^ set(shas.items()))[0][0]
            raise StoreError(f"the copy differs: {user}'s workspace file {first} is not the same")


def check_copy(source: Store, target: Store, instructors: int) -> CopyReport:
    """Compare the copy with its source; :class:`StoreError` names the first difference."""
    before, after = counts(source), counts(target)
    for table in TABLES:
        if before[table] != after[table]:
            raise StoreError(
                f"the copy differs: {table} has {after[table]} row(s) in {target.where}, "
                f"{before[table]} in {source.where}"
            )
    if after.get("instructors", 0) != instructors:
        raise StoreError(f"the copy differs: {after.get('instructors')} instructor(s) copied")
    mine, theirs = source.signoffs.of(), target.signoffs.of()
    if mine != theirs:
        first = next(
            (a.label() for a, b in zip(mine, theirs, strict=False) if a != b), "the last one"
        )
        raise StoreError(f"the copy differs: sign-off record {first} is not the same")
    head, copied = log_head(mine), log_head(theirs)
    if head != copied:
        raise StoreError(f"the copy differs: the log's head is {copied}, not {head}")
    return CopyReport(after, instructors, head)
