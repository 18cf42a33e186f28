"""``workbench instructor``: instructors' signing keys and the roster."""

from __future__ import annotations

import argparse
import getpass
import shlex
import sys
from pathlib import Path

from workbench.labs.signoff.instructors import (
    MIN_PASSPHRASE,
    check_passphrase,
    copy_instructor,
    create_instructor,
    key_path,
)
from workbench.labs.signoff.roster import (
    ROSTER_NAME,
    check_name,
    config_dir,
    load_roster,
    roster_keys,
)
from workbench.labs.signoff.signoff_errors import SignoffError
from workbench.labs.store.store import Store, StoreError, resolve_data_dir, resolve_db

from .common import db_option


def data_dir_option(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "--data-dir",
        help="the workbench's data folder (default: $WORKBENCH_DATA, else the user data folder)",
    )


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("instructor", help="instructors' signing keys and the roster")
    inner = p.add_subparsers(dest="instructor_command", metavar="ACTION", required=True)

    add = inner.add_parser(
        "add", help="create an instructor's key pair and add the public key to the roster"
    )
    add.add_argument("name", help="the instructor's name as shown in sign-off records")
    add.add_argument(
        "--passphrase-stdin",
        action="store_true",
        help="read the passphrase from the first line of standard input (for scripts)",
    )
    _trusted_option(add, "add the public key to this roster file too")
    add.add_argument(
        "--key-from",
        metavar="DIR",
        help="for an instructor already in your trusted roster: the data folder holding their "
        "key, copied to this data folder after the passphrase opens it (default: "
        "$WORKBENCH_DATA, else the user data folder)",
    )
    data_dir_option(add)
    db_option(add)
    add.set_defaults(func=cmd_add)

    ls = inner.add_parser("list", help="list the instructors in the roster")
    _trusted_option(ls, "compare the data folder's roster with this one")
    data_dir_option(ls)
    db_option(ls)
    ls.set_defaults(func=cmd_list)

    console = inner.add_parser(
        "console",
        help="the instructor's console: the class live, the sign-off queue, signing off",
        description="Show every student's exercise and objectives live from the course store, "
        "and the requests for sign-off; open one to sign it off with your key (your "
        "passphrase is typed here) or decline it with a note the student sees.",
    )
    console.add_argument(
        "--unicode", action="store_true", help="draw with Unicode marks (default: plain ASCII)"
    )
    data_dir_option(console)
    db_option(console)
    console.set_defaults(func=cmd_console)


def _trusted_option(parser: argparse.ArgumentParser, what: str) -> None:
    parser.add_argument(
        "--roster",
        metavar="FILE",
        help=f"your own roster, which checking trusts: {what} (default: {ROSTER_NAME} in "
        "$WORKBENCH_CONFIG, else the user config folder)",
    )


def _trusted_path(args: argparse.Namespace) -> Path:
    return Path(args.roster).expanduser() if args.roster else config_dir() / ROSTER_NAME


def fail(message: str) -> int:
    print(f"workbench instructor: {message}", file=sys.stderr)
    return 2


def read_new_passphrase(from_stdin: bool) -> str:
    if from_stdin:
        line = sys.stdin.readline()
        return line[:-1] if line.endswith("\n") else line
    if not sys.stdin.isatty():
        raise SignoffError("no terminal to ask for the passphrase: use --passphrase-stdin")
    print(f"Choose a passphrase of at least {MIN_PASSPHRASE} characters.", file=sys.stderr)
    first = getpass.getpass("Passphrase: ")
    check_passphrase(first)
    if getpass.getpass("Passphrase again: ") != first:
        raise SignoffError("the two passphrases differ; nothing was created")
    return first


def read_passphrase(from_stdin: bool, name: str) -> str:
    """The passphrase of an existing key, asked once."""
    if from_stdin:
        line = sys.stdin.readline()
        return line[:-1] if line.endswith("\n") else line
    if not sys.stdin.isatty():
        raise SignoffError("no terminal to ask for the passphrase: use --passphrase-stdin")
    return getpass.getpass(f"{name}'s passphrase: ")


def _quoted(text: str | Path) -> str:
    return shlex.quote(str(text))


def _add_existing(
    args: argparse.Namespace, name: str, data_dir: Path, trusted: Path, store: Store | None
) -> int:
    """Add an instructor of the trusted roster to another data folder with the same key, or
    say the command that does."""
    entry = load_roster(trusted)[name]
    source = Path(args.key_from).expanduser() if args.key_from else resolve_data_dir(None)
    target = store.where if store is not None else str(data_dir)
    command = (
        f"workbench instructor add {_quoted(name)} --data-dir {_quoted(data_dir)} "
        + (f"--roster {_quoted(trusted)} " if args.roster else "")
        + "--key-from DIR"
    )
    if not key_path(source, name).is_file() or source.resolve() == data_dir.resolve():
        return fail(
            f"{name} is already in your trusted roster {trusted} (key {entry.fingerprint()}), "
            f"and {source} holds no key for {name}. To add that same key to {target}, name "
            f"the data folder that holds it: {command}"
        )
    print(
        f"{name} is already in your trusted roster (key {entry.fingerprint()}): adding that key "
        f"from {source} to {target}",
        file=sys.stderr,
    )
    passphrase = read_passphrase(args.passphrase_stdin, name)
    copy_instructor(source, data_dir, name, passphrase, trusted, store=store)
    print(f"added {name} (key {entry.fingerprint()}) to {target}, the same key as in {source}")
    if store is not None:
        print(f"the private key is encrypted in the course database {target}")
    else:
        print(f"the private key is encrypted in {key_path(data_dir, name)}")
    print(f"your trusted roster {trusted} is unchanged: 'workbench signoff verify' checks with it")
    return 0


def _course_store(args: argparse.Namespace, data_dir: Path) -> Store | None:
    """The course's PostgreSQL store when ``--db``/``$WORKBENCH_DB`` names one, else None
    (the roster and keys stay in the data folder's files)."""
    db = resolve_db(args.db)
    return Store.open(data_dir, db=db) if db else None


def cmd_add(args: argparse.Namespace) -> int:
    data_dir = resolve_data_dir(args.data_dir)
    trusted = _trusted_path(args)
    try:
        store = _course_store(args, data_dir)
    except StoreError as exc:
        return fail(str(exc))
    try:
        name = check_name(args.name)
        where = roster_keys(store, data_dir).where
        if name in roster_keys(store, data_dir).entries():
            raise SignoffError(f"{name} is already in the roster {where}")
        if trusted.resolve().is_relative_to(data_dir.resolve()):
            raise SignoffError(
                f"{trusted} is inside the data folder {data_dir}: keep your own roster "
                "elsewhere (--roster FILE or $WORKBENCH_CONFIG)"
            )
        if name in load_roster(trusted):
            return _add_existing(args, name, data_dir, trusted, store)
        passphrase = read_new_passphrase(args.passphrase_stdin)
        entry = create_instructor(data_dir, name, passphrase, trusted=trusted, store=store)
    except (SignoffError, EOFError) as exc:
        return fail(str(exc) or "no passphrase given")
    except OSError as exc:
        return fail(f"cannot write the key or a roster: {exc}")
    finally:
        if store is not None:
            store.close()
    print(f"added {entry.name} (key {entry.fingerprint()}) to {where}")
    print(f"and to your trusted roster {trusted}, which 'workbench signoff verify' checks with")
    if store is not None:
        print(f"the private key is encrypted in the course database {where}")
    else:
        print(f"the private key is encrypted in {key_path(data_dir, name)}")
    return 0


def cmd_console(args: argparse.Namespace) -> int:
    from workbench.labs.model import LabFileError
    from workbench.tui.console_app import make_console
    from workbench.wire.settings import AppSettings

    try:
        settings = AppSettings(
            data_dir=resolve_data_dir(args.data_dir),
            db=resolve_db(getattr(args, "db", None)),
            unicode=args.unicode,
            role="instructor",
        )
        app = make_console(settings)
    except (StoreError, LabFileError) as exc:
        return fail(str(exc))
    app.run()
    return 0


def cmd_list(args: argparse.Namespace) -> int:
    data_dir = resolve_data_dir(args.data_dir)
    trusted_path = _trusted_path(args)
    try:
        store = _course_store(args, data_dir)
    except StoreError as exc:
        return fail(str(exc))
    try:
        offered = roster_keys(store, data_dir)
        where = offered.where
        roster = offered.entries()
        keys = {name for name in roster if offered.holds_key(name)}
        trusted = load_roster(trusted_path)
    except (SignoffError, StoreError) as exc:
        return fail(str(exc))
    finally:
        if store is not None:
            store.close()
    if not roster:
        print(f"no instructors in {where} (add one: workbench instructor add NAME)")
        return 0
    width = max(len(n) for n in roster)
    for entry in roster.values():
        unlockable = "key here" if entry.name in keys else "public key only"
        kept = trusted.get(entry.name)
        if kept is None:
            trust = "NOT in your trusted roster"
        elif kept.public_key != entry.public_key:
            trust = f"KEY DIFFERS from your trusted roster ({kept.fingerprint()})"
        else:
            trust = "trusted"
        print(
            f"{entry.name:<{width}}  {entry.fingerprint()}  added {entry.added}  {unlockable}  "
            f"{trust}"
        )
    print(f"(trusted roster: {trusted_path})")
    return 0
