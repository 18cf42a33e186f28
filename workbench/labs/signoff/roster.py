"""The instructor roster: who may sign off, with their public keys.

The roster is a JSON file (``{"format": "workbench-roster/1", "instructors": [...]}``) that
anyone may copy and use to check records. The data folder's copy (or, with PostgreSQL, the
database's) is what the app offers to sign with; anyone who can write the data folder can
change it, so checking trusts only a roster the instructor holds (:func:`trusted_roster_path`).

Where the offered roster and the instructors' sealed keys are kept is one interface,
:class:`RosterKeys`, with two kinds: the data folder's files (:class:`FileRosterKeys`, for a
SQLite store) and the course database (:class:`DatabaseRosterKeys`); :func:`roster_keys`
picks the one of a store.
"""

from __future__ import annotations

import base64
import binascii
import hashlib
import json
import os
import re
from dataclasses import dataclass
from pathlib import Path
from typing import Protocol

import platformdirs
from cryptography.hazmat.primitives.asymmetric.ed25519 import Ed25519PublicKey

from workbench.files.atomic import write_text_atomic

from ..names import NameProblem, clean_name
from ..store.instructor_rows import InstructorRows
from ..store.store import APP_NAME, Store, StoreError
from .signoff_errors import SignoffError, UntrustedRoster

ROSTER_FORMAT = "workbench-roster/1"
ROSTER_NAME = "roster.json"
ENV_CONFIG_DIR = "WORKBENCH_CONFIG"
MAX_NAME = 64
#: the data folder's folder of sealed keys (a SQLite store's)
KEYS_DIR = "instructors"


def to_b64(data: bytes) -> str:
    """``data`` as base64 text, as keys and signatures are written in files."""
    return base64.b64encode(data).decode("ascii")


def from_b64(text: object, what: str, where: Path | str) -> bytes:
    """The bytes of base64 ``text``, ``what`` of the file ``where``; :class:`SignoffError`
    naming both if it is not base64."""
    try:
        return base64.b64decode(str(text), validate=True)
    except (binascii.Error, ValueError):
        raise SignoffError(f"{where}: {what} is not base64") from None


def check_name(name: str) -> str:
    """An instructor's name as shown in records, normalised (see :mod:`workbench.labs.names`):
    1-64 characters, one script, nothing invisible."""
    try:
        return clean_name(name, "the instructor's name", MAX_NAME)
    except NameProblem as exc:
        raise SignoffError(str(exc)) from None


def roster_path(data_dir: Path) -> Path:
    """The data folder's roster: the instructors the app offers to sign with."""
    return data_dir / ROSTER_NAME


def config_dir() -> Path:
    """The instructor's configuration folder: ``$WORKBENCH_CONFIG``, else the user config
    folder (``~/.config/viple-workbench`` on Linux)."""
    env = os.environ.get(ENV_CONFIG_DIR)
    if env:
        return Path(env).expanduser()
    return Path(platformdirs.user_config_dir(APP_NAME, appauthor=False))


def _inside(path: Path, folder: Path) -> bool:
    return path.resolve().is_relative_to(folder.resolve())


def trusted_roster_path(option: str | os.PathLike | None, data_dir: Path) -> Path:
    """The roster that checking trusts: ``--roster FILE`` if given, else ``roster.json`` in the
    configuration folder. Neither may lie inside the data folder (whose roster anyone who can
    write there can change): :class:`UntrustedRoster` says so, and what to do."""
    fix = (
        f"pass your own copy with --roster FILE, or keep it as {config_dir() / ROSTER_NAME} "
        f"(${ENV_CONFIG_DIR} chooses the folder); 'workbench instructor add' puts your key there"
    )
    if option:
        path = Path(option).expanduser()
        if not path.is_file():
            raise SignoffError(f"{path}: no such roster file")
        if _inside(path, data_dir):
            raise UntrustedRoster(
                f"{path} is inside the data folder {data_dir}, where students may be able to "
                f"write, so it is not trusted: {fix}"
            )
        return path
    path = config_dir() / ROSTER_NAME
    if _inside(path, data_dir):
        raise UntrustedRoster(
            f"the configuration folder {config_dir()} is inside the data folder {data_dir}, "
            f"so its roster is not trusted: {fix}"
        )
    if not path.is_file():
        raise UntrustedRoster(
            f"no trusted roster: the data folder's {roster_path(data_dir)} is not trusted on its "
            f"own (anyone who can write the data folder can change it); {fix}"
        )
    return path


@dataclass(frozen=True)
class RosterEntry:
    name: str
    public_key: str
    added: str

    def key(self) -> Ed25519PublicKey:
        raw = from_b64(self.public_key, f"the public key of {self.name}", "roster")
        try:
            return Ed25519PublicKey.from_public_bytes(raw)
        except ValueError:
            raise SignoffError(f"roster: the public key of {self.name} is not Ed25519") from None

    def fingerprint(self) -> str:
        raw = base64.b64decode(self.public_key)
        return hashlib.sha256(raw).hexdigest()[:16]


def load_roster(path: Path) -> dict[str, RosterEntry]:
    """The roster by instructor name; a missing file is an empty roster."""
    try:
        text = path.read_text(encoding="utf-8")
    except FileNotFoundError:
        return {}
    except OSError as exc:
        raise SignoffError(f"{path}: cannot read the roster: {exc.strerror}") from None
    try:
        data = json.loads(text)
    except json.JSONDecodeError as exc:
        raise SignoffError(
            f"{path}: the roster is not JSON (line {exc.lineno}: {exc.msg})"
        ) from None
    if not isinstance(data, dict) or data.get("format") != ROSTER_FORMAT:
        raise SignoffError(f'{path}: not a roster (expected "format": "{ROSTER_FORMAT}")')
    entries = data.get("instructors")
    if not isinstance(entries, list):
        raise SignoffError(f'{path}: "instructors" must be a list')
    roster: dict[str, RosterEntry] = {}
    for i, item in enumerate(entries):
        if not isinstance(item, dict) or not all(
            isinstance(item.get(k), str) for k in ("name", "public_key")
        ):
            raise SignoffError(f"{path}: instructor #{i + 1} needs a name and a public_key")
        try:
            name = check_name(item["name"])
        except SignoffError as exc:
            raise SignoffError(f"{path}: instructor #{i + 1} {item['name']!r}: {exc}") from None
        if name != item["name"]:
            raise SignoffError(
                f"{path}: instructor #{i + 1} {item['name']!r} is not written in Unicode's "
                f"normal form (NFKC, no outer spaces): write it as {name!r}"
            )
        if name in roster:
            raise SignoffError(f"{path}: {name} is listed twice")
        entry = RosterEntry(name, item["public_key"], str(item.get("added", "")))
        from_b64(entry.public_key, f"the public key of {entry.name}", path)
        roster[entry.name] = entry
    return roster


def save_roster(path: Path, roster: dict[str, RosterEntry]) -> None:
    data = {
        "format": ROSTER_FORMAT,
        "instructors": [
            {"name": e.name, "public_key": e.public_key, "added": e.added} for e in roster.values()
        ],
    }
    path.parent.mkdir(parents=True, exist_ok=True)
    write_text_atomic(path, json.dumps(data, indent=2, ensure_ascii=False) + "\n")


def _slug(name: str) -> str:
    slug = re.sub(r"[^a-z0-9]+", "-", name.lower()).strip("-")
    digest = hashlib.sha256(name.encode("utf-8")).hexdigest()[:8]
    return f"{slug or 'instructor'}-{digest}"


def key_path(data_dir: Path, name: str) -> Path:
    """The data folder's file of ``name``'s sealed key."""
    return data_dir / KEYS_DIR / f"{_slug(name)}.key.json"


class RosterKeys(Protocol):
    """Where the offered roster and the instructors' sealed keys are kept."""

    #: the place of the roster, and of the keys, as messages name them
    where: str
    keys_at: str
    #: reading it takes no time worth a thread (files on this machine)
    reads_at_once: bool

    def entries(self) -> dict[str, RosterEntry]:
        """The roster by instructor name (:class:`SignoffError` when it cannot be read)."""
        ...

    def key_text(self, name: str) -> tuple[str | None, str]:
        """The sealed key file (JSON text) of ``name`` (None when there is none), and where
        it is kept, as messages name it."""
        ...

    def holds_key(self, name: str) -> bool:
        """Whether a sealed key of ``name`` is kept here (a roster entry may have none)."""
        ...

    def add(self, entry: RosterEntry, key_text: str) -> None:
        """Keep a new instructor's entry and sealed key (never over another)."""
        ...


class FileRosterKeys:
    """The data folder's ``roster.json`` and its ``instructors/`` key files."""

    reads_at_once = True

    def __init__(self, data_dir: Path) -> None:
        self.data_dir = data_dir
        self.where = str(roster_path(data_dir))
        self.keys_at = str(data_dir / KEYS_DIR)

    def entries(self) -> dict[str, RosterEntry]:
        return load_roster(roster_path(self.data_dir))

    def key_text(self, name: str) -> tuple[str | None, str]:
        path = key_path(self.data_dir, name)
        try:
            return path.read_text(encoding="utf-8"), str(path)
        except FileNotFoundError:
            return None, str(path)
        except OSError as exc:
            raise SignoffError(f"{path}: cannot read the key: {exc.strerror}") from None

    def holds_key(self, name: str) -> bool:
        return key_path(self.data_dir, name).exists()

    def add(self, entry: RosterEntry, key_text: str) -> None:
        target = key_path(self.data_dir, entry.name)
        if target.exists():
            raise SignoffError(f"{target}: a key for {entry.name} already exists")
        roster = self.entries()
        target.parent.mkdir(parents=True, exist_ok=True)
        fd = os.open(target, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o600)
        with os.fdopen(fd, "w", encoding="utf-8") as fh:
            fh.write(key_text)
            fh.flush()
            os.fsync(fh.fileno())
        roster[entry.name] = entry
        save_roster(roster_path(self.data_dir), roster)


class DatabaseRosterKeys:
    """The course database's ``instructors`` table: each entry with its sealed key."""

    reads_at_once = False

    def __init__(self, rows: InstructorRows, where: str) -> None:
        self.rows = rows
        self.where = where
        self.keys_at = where

    def entries(self) -> dict[str, RosterEntry]:
        try:
            rows = self.rows.entries()
        except StoreError as exc:
            raise SignoffError(str(exc)) from None
        return {name: RosterEntry(name, key, added) for name, key, added in rows}

    def key_text(self, name: str) -> tuple[str | None, str]:
        try:
            return self.rows.key_file(name), f"{self.where} (instructors: {name})"
        except StoreError as exc:
            raise SignoffError(str(exc)) from None

    def holds_key(self, name: str) -> bool:
        return self.key_text(name)[0] is not None

    def add(self, entry: RosterEntry, key_text: str) -> None:
        try:
            self.rows.add(entry.name, entry.public_key, entry.added, key_text)
        except StoreError as exc:
            raise SignoffError(str(exc)) from None


def roster_keys(store: Store | None, data_dir: Path | None = None) -> RosterKeys:
    """Where ``store`` keeps the roster and keys: the course database's table when it has
    one, else the files of ``data_dir`` (default: the store's data folder)."""
    if store is not None and store.instructors is not None:
        return DatabaseRosterKeys(store.instructors, store.where)
    folder = data_dir if data_dir is not None else store.data_dir if store is not None else None
    if folder is None:
        raise ValueError("a roster in files needs a data folder")
    return FileRosterKeys(folder)


def roster_names(store: Store) -> tuple[list[str], str]:
    """The names one may sign as, sorted, and the problem to show when there are none (it
    says how to add one). Reads a course database: call it off the event loop."""
    try:
        names = sorted(offered_roster(store))
        problem = "" if names else "the roster has no instructors yet"
    except (SignoffError, StoreError) as exc:
        names, problem = [], str(exc)
    if problem:
        problem += ": add one with 'workbench instructor add NAME'"
    return names, problem


def offered_roster(store: Store) -> dict[str, RosterEntry]:
    """The instructors the app offers to sign with: the database's roster (PostgreSQL) or
    the data folder's ``roster.json`` (SQLite). Neither is trusted for checking."""
    return roster_keys(store).entries()
