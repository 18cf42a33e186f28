"""``workbench signoff``: list, verify and export the signed sign-off records."""

from __future__ import annotations

import argparse
import csv
import io
import sys
from pathlib import Path

from workbench.labs.signoff import (
    GRADEBOOK_COLUMNS,
    SignoffError,
    gradebook_rows,
    load_roster,
    roster_path,
    verify_all,
)
from workbench.labs.store import Store, StoreError
from workbench.sim.mazefile import write_text_atomic

from .instructor import data_dir_option

CHECKS = (
    "each record's signature, over every field, by its instructor's key in the roster; "
    "the run record's SHA-256 digest where the file is present"
)


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("signoff", help="list, verify or export instructors' sign-offs")
    inner = p.add_subparsers(dest="signoff_command", metavar="ACTION", required=True)

    ls = inner.add_parser("list", help="list the sign-off records")
    ls.add_argument("--student", help="only this student (either member of a pair)")
    ls.add_argument("--lab", help="only this lab")
    data_dir_option(ls)
    ls.set_defaults(func=cmd_list)

    ver = inner.add_parser(
        "verify", help="check every record's signature and evidence; exit 1 if any fails"
    )
    _roster_option(ver)
    data_dir_option(ver)
    ver.set_defaults(func=cmd_verify)

    exp = inner.add_parser("export", help="write a gradebook CSV: one row per student and exercise")
    exp.add_argument("--csv", required=True, metavar="FILE", help="the CSV file to write")
    _roster_option(exp)
    data_dir_option(exp)
    exp.set_defaults(func=cmd_export)


def _roster_option(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "--roster",
        metavar="FILE",
        help="check against this roster (e.g. the course's own copy; default: the data folder's)",
    )


def fail(message: str) -> int:
    print(f"workbench signoff: {message}", file=sys.stderr)
    return 2


def _open(args: argparse.Namespace) -> Store:
    return Store.open(args.data_dir, create=False)


def _roster(args: argparse.Namespace, store: Store):
    if args.roster:
        path = Path(args.roster)
        if not path.is_file():
            raise SignoffError(f"{path}: no such roster file")
    else:
        path = roster_path(store.data_dir)
    return path, load_roster(path)


def cmd_list(args: argparse.Namespace) -> int:
    try:
        with _open(args) as store:
            rows = store.signoffs(student=args.student, lab=args.lab)
    except StoreError as exc:
        return fail(str(exc))
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
        print(f"#{r.id}  {r.signed_at}  {who}  {r.lab}/{r.exercise}  by {r.instructor}{tail}")
    print("(not verified here: run 'workbench signoff verify')")
    return 0


def cmd_verify(args: argparse.Namespace) -> int:
    try:
        with _open(args) as store:
            path, roster = _roster(args, store)
            verdicts = verify_all(store, roster)
    except (StoreError, SignoffError) as exc:
        return fail(str(exc))
    print(f"checked {len(verdicts)} record(s) against the roster {path}:")
    print(f"  {CHECKS}")
    bad = [v for v in verdicts if not v.ok]
    for v in verdicts:
        r = v.row
        label = f"#{r.id} {r.student}{' & ' + r.partner if r.partner else ''} {r.lab}/{r.exercise}"
        for problem in v.problems:
            print(f"FAIL {label}: {problem}")
        for note in v.notes:
            print(f"note {label}: {note}")
    if bad:
        print(f"{len(bad)} of {len(verdicts)} record(s) do NOT verify")
        return 1
    print(f"all {len(verdicts)} record(s) verify")
    return 0


def cmd_export(args: argparse.Namespace) -> int:
    try:
        with _open(args) as store:
            _, roster = _roster(args, store)
            verdicts = verify_all(store, roster)
    except (StoreError, SignoffError) as exc:
        return fail(str(exc))
    rows = gradebook_rows([v.row for v in verdicts if v.ok])
    out = io.StringIO()
    writer = csv.DictWriter(out, fieldnames=GRADEBOOK_COLUMNS, lineterminator="\n")
    writer.writeheader()
    writer.writerows(rows)
    target = Path(args.csv)
    try:
        write_text_atomic(target, out.getvalue())
    except OSError as exc:
        return fail(f"{target}: cannot write: {exc.strerror}")
    print(f"wrote {len(rows)} row(s) to {target}")
    left_out = sum(1 for v in verdicts if not v.ok)
    if left_out:
        print(
            f"{left_out} record(s) do not verify and were left out "
            "(see 'workbench signoff verify')",
            file=sys.stderr,
        )
    return 0
