"""Moving a data folder's SQLite store into a course's PostgreSQL database, checked after.

Everything moves: the sign-off log (each record with its id, sequence number and hashes, so
the log's head stays the same), progress, places, drivers, lockouts, the failed-attempt log,
and the instructors of the data folder's roster with their encrypted key files. The target
must hold none of these yet; the copy is one transaction, so a failure leaves it as it was.
Afterwards both stores are read again and compared: the number of rows of every table, every
sign-off record, the log's head and the roster.
"""

from __future__ import annotations

from dataclasses import dataclass

from .instructors import key_path
from .roster import load_roster, roster_path
from .signlog import Head
from .store import SIGNOFF_COLUMNS, Store, StoreError
from .verify import log_head

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


def counts(store: Store) -> dict[str, int]:
    out = {table: int(store._read(f"SELECT count(*) FROM {table}")[0][0]) for table in TABLES}
    if store.keeps_roster:
        out["instructors"] = int(store._read("SELECT count(*) FROM instructors")[0][0])
    return out


def copy_store(source: Store, target: Store) -> CopyReport:
    """Copy the SQLite ``source`` into the empty PostgreSQL ``target``, then check the copy;
    :class:`StoreError` says what is in the way or what differs."""
    if source.keeps_roster or not target.keeps_roster:
        raise StoreError("the copy goes from a data folder's SQLite store to PostgreSQL")
    already = {t: n for t, n in counts(target).items() if n}
    if already:
        held = ", ".join(f"{n} {t}" for t, n in already.items())
        raise StoreError(
            f"{target.where} already holds {held}: move a data folder into an empty database "
            "(or one made for it with CREATE DATABASE)"
        )
    roster = load_roster(roster_path(source.data_dir))
    keys = {}
    for name in roster:
        path = key_path(source.data_dir, name)
        keys[name] = path.read_text(encoding="utf-8") if path.is_file() else None
    rows = {t: source._read(f"SELECT {', '.join(c)} FROM {t}") for t, c in TABLES.items()}
    with target._write() as tx:
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
    return check_copy(source, target, len(roster))


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
    mine, theirs = source.signoffs(), target.signoffs()
    if mine != theirs:
        first = next(
            (a.label() for a, b in zip(mine, theirs, strict=False) if a != b), "the last one"
        )
        raise StoreError(f"the copy differs: sign-off record {first} is not the same")
    head, copied = log_head(mine), log_head(theirs)
    if head != copied:
        raise StoreError(f"the copy differs: the log's head is {copied}, not {head}")
    return CopyReport(after, instructors, head)
