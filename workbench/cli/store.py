"""``workbench store``: where progress, sign-offs and the roster are kept.

``store migrate --to postgresql://...`` moves a data folder's SQLite store into a course's
PostgreSQL database and checks the copy; ``store info`` says which store a command would use
and what it holds.
"""

from __future__ import annotations

import argparse
import sys

from workbench.labs.signoff.verify import log_head
from workbench.labs.store.database import StoreError, resolve_db
from workbench.labs.store.store import Store, resolve_data_dir
from workbench.labs.storecopy import copy_store, counts

from .common import db_option
from .instructor import data_dir_option


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("store", help="where progress, sign-offs and the roster are kept")
    inner = p.add_subparsers(dest="store_command", metavar="ACTION", required=True)

    mig = inner.add_parser(
        "migrate",
        help="copy the data folder's SQLite store into an empty PostgreSQL database, then "
        "check the copy",
    )
    mig.add_argument(
        "--to", required=True, metavar="URL", help="the PostgreSQL database (postgresql://...)"
    )
    data_dir_option(mig)
    mig.set_defaults(func=cmd_migrate)

    info = inner.add_parser("info", help="which store is used, its schema steps and its size")
    data_dir_option(info)
    db_option(info)
    info.set_defaults(func=cmd_info)


def fail(message: str, code: int = 1) -> int:
    print(f"workbench store: {message}", file=sys.stderr)
    return code


def cmd_migrate(args: argparse.Namespace) -> int:
    data_dir = resolve_data_dir(args.data_dir)
    try:
        url = resolve_db(args.to)
    except StoreError as exc:
        return fail(str(exc).replace("--db", "--to", 1), 2)
    if url is None:
        return fail("--to needs a postgresql:// URL", 2)
    try:
        with Store.open(data_dir, create=False) as source, Store.open(data_dir, db=url) as target:
            report = copy_store(source, target)
    except StoreError as exc:
        return fail(f"{exc}\nnothing was copied, or the copy did not check out (see above)")
    print(f"copied {source.where} into {target.where} and checked it:")
    for table, n in report.counts.items():
        print(f"  {table:<12} {n} row(s), the same in both")
    print(f"  sign-off log head {report.head}, the same in both")
    files = sum(report.workspaces.values())
    print(
        f"  workspaces   {files} file(s) of {len(report.workspaces)} student(s), the same in both"
    )
    for why in report.left:
        print(f"  left in the data folder only: {why}")
    print(
        "from now on give every lab server and command --db URL (or set $WORKBENCH_DB); the "
        f"SQLite file {source.where} is left as it was: keep it as a backup"
    )
    return 0


def cmd_info(args: argparse.Namespace) -> int:
    data_dir = resolve_data_dir(args.data_dir)
    try:
        db = resolve_db(args.db)
        with Store.open(data_dir, db=db, create=bool(db)) as store:
            steps = store.migrations()
            sizes = counts(store)
            head = log_head(store.signoffs.of())
            where = store.where
    except StoreError as exc:
        return fail(str(exc))
    print(f"store: {where} ({'PostgreSQL' if db else 'SQLite'})")
    print("schema steps: " + ", ".join(f"{v} {name}" for v, name in steps))
    print("rows: " + ", ".join(f"{t} {n}" for t, n in sizes.items()))
    print(f"sign-off log head {head}")
    return 0
