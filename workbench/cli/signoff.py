"""``workbench signoff``: list, verify and export the signed sign-off log.

All three only read the database (SQLite's read-only mode, or a read-only PostgreSQL session
with ``--db``/``$WORKBENCH_DB``: the whole course's log). ``verify`` and ``export`` trust
only the instructor's own roster (``--roster FILE`` or the configuration folder's), print the
log's head for the instructor to keep, and take a kept head back (``--head``,
``--head-from``) to find a log that was cut short or rolled back.
"""

from __future__ import annotations

import argparse
import csv
import io
import sys
from pathlib import Path

from workbench.files.atomic import write_text_atomic
from workbench.files.spreadsheet import spreadsheet_cell
from workbench.labs.classview import profiles
from workbench.labs.model import LabFileError, load_labs
from workbench.labs.signlog import Head, LogError
from workbench.labs.signoff.gradebook import GRADEBOOK_COLUMNS, gradebook_rows, head_from_gradebook
from workbench.labs.signoff.roster import load_roster, roster_path, trusted_roster_path
from workbench.labs.signoff.signoff_errors import SignoffError, UntrustedRoster
from workbench.labs.signoff.verify import LogVerdict, course_evidence, verify_log
from workbench.labs.store.store import (
    StoreDiskError,
    StoredSignoff,
    StoreError,
    read_signoffs,
    resolve_data_dir,
    resolve_db,
)

from .common import db_option
from .instructor import data_dir_option

CHECKS = (
    "each record's signature, over every field and its place in the log, by its instructor's "
    "key in the trusted roster; the chain linking every record to the one before it; the run "
    "record's SHA-256 digest where the file is present (here, or in the course database)"
)


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("signoff", help="list, verify or export instructors' sign-offs")
    inner = p.add_subparsers(dest="signoff_command", metavar="ACTION", required=True)

    ls = inner.add_parser("list", help="list the sign-off records (without checking them)")
    ls.add_argument("--student", help="only this student (either member of a pair)")
    ls.add_argument("--lab", help="only this lab")
    data_dir_option(ls)
    db_option(ls)
    ls.set_defaults(func=cmd_list)

    ver = inner.add_parser(
        "verify",
        help="check every record and the chain that links them; exit 1 if anything fails",
    )
    _trust_options(ver)
    data_dir_option(ver)
    db_option(ver)
    ver.set_defaults(func=cmd_verify)

    exp = inner.add_parser("export", help="write a gradebook CSV: one row per student and exercise")
    exp.add_argument("--csv", required=True, metavar="FILE", help="the CSV file to write")
    _trust_options(exp)
    data_dir_option(exp)
    db_option(exp)
    exp.set_defaults(func=cmd_export)


def _trust_options(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "--roster",
        metavar="FILE",
        help="your own copy of the roster (default: roster.json in $WORKBENCH_CONFIG, else the "
        "user config folder; the data folder's copy is never trusted)",
    )
    kept = parser.add_mutually_exclusive_group()
    kept.add_argument(
        "--head",
        metavar="SEQ:HASH",
        help="a head of the log you kept (verify and export print it): the log must still hold it",
    )
    kept.add_argument(
        "--head-from",
        metavar="CSV",
        help="take the kept head from a gradebook exported earlier (its log_head column)",
    )


def fail(message: str, code: int = 2) -> int:
    print(f"workbench signoff: {message}", file=sys.stderr)
    return code


class _Refused(Exception):
    def __init__(self, message: str, code: int):
        super().__init__(message)
        self.code = code


def _kept_head(args: argparse.Namespace) -> Head | None:
    try:
        if args.head:
            return Head.parse(args.head, "--head")
        if args.head_from:
            return head_from_gradebook(Path(args.head_from))
    except (LogError, SignoffError) as exc:
        raise _Refused(str(exc), 2) from None
    return None


def _checked_log(args: argparse.Namespace) -> tuple[Path, LogVerdict]:
    """The log checked against the trusted roster and the kept head; :class:`_Refused` with
    exit 2 for a wrong command line, 1 when there is nothing trustworthy to check."""
    data_dir = resolve_data_dir(args.data_dir)
    kept = _kept_head(args)
    try:
        db = resolve_db(args.db)
    except StoreError as exc:
        raise _Refused(str(exc), 2) from None
    try:
        path = trusted_roster_path(args.roster, data_dir)
        roster = load_roster(path)
    except UntrustedRoster as exc:
        raise _Refused(f"{exc}\nthe records were NOT checked", 1) from None
    except SignoffError as exc:
        raise _Refused(str(exc), 2) from None
    try:
        local = {} if db else load_roster(roster_path(data_dir))
    except SignoffError:
        local = {}  # only used to explain a signature by another key
    try:
        rows = read_signoffs(data_dir, db)
    except StoreDiskError as exc:  # the disk failed, not the log: it is not known to be bad
        raise _Refused(f"{exc}\nthe records were NOT checked", 1) from None
    except StoreError as exc:  # LogMissing too: no log where one should be
        raise _Refused(f"{exc}\nthe log does NOT verify", 1) from None
    with course_evidence(db) as evidence:  # run records not on this machine's disk
        return path, verify_log(rows, roster, kept, local, evidence)


def cmd_list(args: argparse.Namespace) -> int:
    try:
        rows = read_signoffs(resolve_data_dir(args.data_dir), resolve_db(args.db))
    except StoreError as exc:
        return fail(str(exc))
    if args.student:
        rows = [r for r in rows if args.student in (r.student, r.partner)]
    if args.lab:
        rows = [r for r in rows if r.lab == args.lab]
    if not rows:
        print("no sign-off records" + (" match" if args.student or args.lab else ""))
        return 0
    for r in rows:
        who = f"{r.student} & {r.partner}" if r.partner else r.student
        extra = []
        if r.driver:
            extra.append(f"driver {r.driver}")
        if r.override:
            extra.append("OVERRIDE")
        if r.note:
            extra.append(f"note: {r.note}")
        tail = f"  ({'; '.join(extra)})" if extra else ""
        print(f"{r.label()}  {r.signed_at}  {who}  {r.lab}/{r.exercise}  by {r.instructor}{tail}")
    print("(not verified here: run 'workbench signoff verify')")
    return 0


def _label(r: StoredSignoff) -> str:
    return f"{r.label()} {r.student}{' & ' + r.partner if r.partner else ''} {r.lab}/{r.exercise}"


def cmd_verify(args: argparse.Namespace) -> int:
    try:
        path, log = _checked_log(args)
    except _Refused as exc:
        return fail(str(exc), exc.code)
    total = len(log.verdicts)
    print(f"checked {total} record(s) against the trusted roster {path}:")
    print(f"  {CHECKS}")
    if args.head or args.head_from:
        print("  and that the log still holds the head you kept")
    for problem in log.breaks:
        print(f"FAIL log: {problem}")
    for v in log.verdicts:
        for problem in v.problems:
            print(f"FAIL {_label(v.row)}: {problem}")
        for note in v.notes:
            print(f"note {_label(v.row)}: {note}")
    bad = sum(1 for v in log.verdicts if not v.ok)
    if log.legacy:
        print(f"{log.legacy} legacy record(s), signed before the log was chained")
    if not log.ok:
        if bad:
            print(f"{bad} of {total} record(s) do NOT verify")
        if log.breaks:
            print(f"the log is broken in {len(log.breaks)} place(s) (FAIL log above)")
        print(f"the log does NOT verify (head as found {log.head})")
        return 1
    if total == 0:
        print(f"the log is empty: no sign-off records (head {log.head})")
    else:
        print(f"all {total} record(s) verify")
        print(f"head {log.head}  (keep it: 'verify --head {log.head}' finds a log cut short)")
    return 0


def _exercise_profiles() -> dict[tuple[str, str], str]:
    """Each exercise's profile, for the unit of records that name none (none when the lab
    files cannot be read: those rows then leave the unit empty)."""
    try:
        return profiles(load_labs())
    except LabFileError:
        return {}


def cmd_export(args: argparse.Namespace) -> int:
    try:
        _, log = _checked_log(args)
    except _Refused as exc:
        return fail(str(exc), exc.code)
    if log.breaks:
        for problem in log.breaks:
            print(f"FAIL log: {problem}", file=sys.stderr)
        return fail("the log is broken, so no gradebook was written (see 'signoff verify')", 1)
    rows = gradebook_rows(log.verified_rows(), log.head, _exercise_profiles())
    out = io.StringIO()
    writer = csv.DictWriter(out, fieldnames=GRADEBOOK_COLUMNS, lineterminator="\n")
    writer.writeheader()
    writer.writerows({k: spreadsheet_cell(v) for k, v in row.items()} for row in rows)
    target = Path(args.csv)
    try:
        write_text_atomic(target, out.getvalue())
    except OSError as exc:
        return fail(f"{target}: cannot write: {exc.strerror}")
    print(f"wrote {len(rows)} row(s) to {target}")
    print(f"head {log.head}  (also in the log_head column: 'verify --head-from {target}')")
    left_out = sum(1 for v in log.verdicts if not v.ok)
    if left_out:
        print(
            f"{left_out} record(s) do not verify and were left out "
            "(see 'workbench signoff verify')",
            file=sys.stderr,
        )
    return 0
