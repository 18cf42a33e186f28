"""Instructor keys and signed sign-off records.

An instructor has an Ed25519 key pair. The public key is listed in the roster (a JSON file that
anyone may copy and use to check records); the private key is kept in the data folder,
encrypted with AES-256-GCM under a key derived from the instructor's passphrase by scrypt.
A sign-off record is turned into canonical JSON bytes and signed; verifying rebuilds the same
bytes from the stored columns, so changing any of them breaks the signature. The records form
the hash-chained log of :mod:`workbench.labs.signlog`.

Checking trusts only an instructor-held roster (:func:`trusted_roster_path`): the copy in the
data folder is what the app offers to sign with, and anyone who can write the data folder can
change it.
"""

from __future__ import annotations

import base64
import binascii
import csv
import hashlib
import json
import logging
import math
import os
import re
import secrets
from collections.abc import Callable
from dataclasses import dataclass, field, replace
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

import platformdirs
from cryptography.exceptions import InvalidSignature, InvalidTag
from cryptography.hazmat.primitives import serialization
from cryptography.hazmat.primitives.asymmetric.ed25519 import Ed25519PrivateKey, Ed25519PublicKey
from cryptography.hazmat.primitives.ciphers.aead import AESGCM
from cryptography.hazmat.primitives.kdf.scrypt import Scrypt

from workbench.files.atomic import write_text_atomic
from workbench.sim.record import file_sha256

from . import signlog
from .names import NameProblem, check_student, clean_name
from .signlog import Head, LogError
from .store import APP_NAME, Store, StoredSignoff, StoreError, utc_iso

log = logging.getLogger(__name__)

KEY_FORMAT = "workbench-instructor-key/1"
ROSTER_FORMAT = "workbench-roster/1"
RECORD_FORMAT = signlog.RECORD_FORMAT
ROSTER_NAME = "roster.json"
ENV_CONFIG_DIR = "WORKBENCH_CONFIG"
KEYS_DIR = "instructors"
MIN_PASSPHRASE = 10
MAX_NAME = 64
FAILURE_LIMIT = 5
LOCK_SECONDS = 60.0


class SignoffError(ValueError):
    """A sign-off, key or roster problem, with a message meant for the user."""


class PassphraseTooShort(SignoffError):
    pass


class WrongPassphrase(SignoffError):
    pass


class LockedOut(SignoffError):
    def __init__(self, instructor: str, seconds: float):
        self.seconds = seconds
        super().__init__(
            f"sign-off by {instructor} is locked for {math.ceil(seconds)} s more after "
            f"{FAILURE_LIMIT} wrong passphrases"
        )


class UnknownInstructor(SignoffError):
    pass


class UntrustedRoster(SignoffError):
    """No roster that students cannot write was found or given."""


@dataclass(frozen=True)
class KdfParams:
    """scrypt cost: n (a power of two), r, p. The defaults take ~128 MiB and a fraction of a
    second; pass cheaper ones explicitly only in tests."""

    n: int = 2**17
    r: int = 8
    p: int = 1

    def __post_init__(self) -> None:
        if self.n < 2 or self.n & (self.n - 1) or self.r < 1 or self.p < 1:
            raise SignoffError(f"bad scrypt parameters n={self.n} r={self.r} p={self.p}")


def _b64(data: bytes) -> str:
    return base64.b64encode(data).decode("ascii")


def _unb64(text: object, what: str, where: Path | str) -> bytes:
    try:
        return base64.b64decode(str(text), validate=True)
    except (binascii.Error, ValueError):
        raise SignoffError(f"{where}: {what} is not base64") from None


def _now() -> datetime:
    return datetime.now(UTC)


# names and files


def check_name(name: str) -> str:
    """An instructor's name as shown in records, normalised (see :mod:`workbench.labs.names`):
    1-64 characters, one script, nothing invisible."""
    try:
        return clean_name(name, "the instructor's name", MAX_NAME)
    except NameProblem as exc:
        raise SignoffError(str(exc)) from None


def _slug(name: str) -> str:
    slug = re.sub(r"[^a-z0-9]+", "-", name.lower()).strip("-")
    digest = hashlib.sha256(name.encode("utf-8")).hexdigest()[:8]
    return f"{slug or 'instructor'}-{digest}"


def key_path(data_dir: Path, name: str) -> Path:
    return data_dir / KEYS_DIR / f"{_slug(name)}.key.json"


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


def check_passphrase(passphrase: str) -> None:
    if len(passphrase) < MIN_PASSPHRASE:
        raise PassphraseTooShort(
            f"the passphrase must be at least {MIN_PASSPHRASE} characters long "
            f"(it has {len(passphrase)})"
        )


# the roster


@dataclass(frozen=True)
class RosterEntry:
    name: str
    public_key: str
    added: str

    def key(self) -> Ed25519PublicKey:
        raw = _unb64(self.public_key, f"the public key of {self.name}", "roster")
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
        _unb64(entry.public_key, f"the public key of {entry.name}", path)
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


# instructor keys


@dataclass(frozen=True)
class Instructor:
    """An instructor whose private key has been unlocked with the passphrase."""

    name: str
    private_key: Ed25519PrivateKey = field(repr=False)

    def public_key_b64(self) -> str:
        raw = self.private_key.public_key().public_bytes(
            serialization.Encoding.Raw, serialization.PublicFormat.Raw
        )
        return _b64(raw)

    def sign(self, data: bytes) -> str:
        return _b64(self.private_key.sign(data))


def _derive(passphrase: str, salt: bytes, params: KdfParams) -> bytes:
    kdf = Scrypt(salt=salt, length=32, n=params.n, r=params.r, p=params.p)
    return kdf.derive(passphrase.encode("utf-8"))


def _aad(name: str, public_key: str) -> bytes:
    return f"{KEY_FORMAT}\n{name}\n{public_key}".encode()


def create_instructor(
    data_dir: Path,
    name: str,
    passphrase: str,
    kdf: KdfParams | None = None,
    now: datetime | None = None,
    trusted: Path | None = None,
    store: Store | None = None,
) -> RosterEntry:
    """Make a key pair: the private key is saved encrypted, the public key joins the store's
    roster (the data folder's files, or the database of a PostgreSQL ``store``, which holds
    the encrypted key as well) and, given ``trusted`` (the instructor's own roster file),
    that one too."""
    name = check_name(name)
    check_passphrase(passphrase)
    params = kdf or KdfParams()
    in_database = store is not None and store.keeps_roster
    roster_file = roster_path(data_dir)
    roster = offered_roster(store) if in_database else load_roster(roster_file)
    if name in roster:
        where = store.where if in_database and store is not None else roster_file
        raise SignoffError(f"{name} is already in the roster {where}")
    kept = load_roster(trusted) if trusted is not None else {}
    if name in kept:
        raise SignoffError(
            f"{name} is already in your trusted roster {trusted} with another key: choose "
            "another name, or remove the old entry from that file first"
        )
    target = key_path(data_dir, name)
    if not in_database and target.exists():
        raise SignoffError(f"{target}: a key for {name} already exists")
    private = Ed25519PrivateKey.generate()
    instructor = Instructor(name, private)
    public = instructor.public_key_b64()
    salt = secrets.token_bytes(16)
    nonce = secrets.token_bytes(12)
    raw = private.private_bytes(
        serialization.Encoding.Raw, serialization.PrivateFormat.Raw, serialization.NoEncryption()
    )
    sealed = AESGCM(_derive(passphrase, salt, params)).encrypt(nonce, raw, _aad(name, public))
    data = {
        "format": KEY_FORMAT,
        "name": name,
        "public_key": public,
        "kdf": {"name": "scrypt", "n": params.n, "r": params.r, "p": params.p, "salt": _b64(salt)},
        "cipher": {"name": "AES-256-GCM", "nonce": _b64(nonce)},
        "encrypted_private_key": _b64(sealed),
    }
    entry = RosterEntry(name, public, utc_iso(now or _now()))
    if in_database and store is not None:
        try:
            store.add_instructor(name, public, entry.added, json.dumps(data, indent=2) + "\n")
        except StoreError as exc:
            raise SignoffError(str(exc)) from None
    else:
        target.parent.mkdir(parents=True, exist_ok=True)
        fd = os.open(target, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o600)
        with os.fdopen(fd, "w", encoding="utf-8") as fh:
            fh.write(json.dumps(data, indent=2) + "\n")
            fh.flush()
            os.fsync(fh.fileno())
        roster[name] = entry
        save_roster(roster_file, roster)
    if trusted is not None:
        kept[name] = entry
        save_roster(trusted, kept)
    return entry


def offered_roster(store: Store) -> dict[str, RosterEntry]:
    """The instructors the app offers to sign with: the database's roster (PostgreSQL) or
    the data folder's ``roster.json`` (SQLite). Neither is trusted for checking."""
    if not store.keeps_roster:
        return load_roster(roster_path(store.data_dir))
    try:
        rows = store.roster_rows()
    except StoreError as exc:
        raise SignoffError(str(exc)) from None
    return {name: RosterEntry(name, key, added) for name, key, added in rows}


def unlock_instructor(
    data_dir: Path, name: str, passphrase: str, store: Store | None = None
) -> Instructor:
    """Decrypt an instructor's private key (from the data folder, or from the database of a
    PostgreSQL ``store``); :class:`WrongPassphrase` if it does not open."""
    path: Path | str = key_path(data_dir, name)
    try:
        if store is not None and store.keeps_roster:
            path = f"{store.where} (instructors: {name})"
            text = store.instructor_key(name)
            if text is None:
                raise FileNotFoundError(path)
        else:
            text = Path(path).read_text(encoding="utf-8")
        data = json.loads(text)
    except FileNotFoundError:
        where = store.where if store is not None and store.keeps_roster else Path(path).parent
        raise UnknownInstructor(
            f"no key for instructor {name} in {where} (create it with 'workbench instructor add')"
        ) from None
    except StoreError as exc:
        raise SignoffError(str(exc)) from None
    except OSError as exc:
        raise SignoffError(f"{path}: cannot read the key: {exc.strerror}") from None
    except json.JSONDecodeError:
        raise SignoffError(f"{path}: the key file is not JSON") from None
    try:
        if data["format"] != KEY_FORMAT or data["name"] != name:
            raise SignoffError(f"{path}: not the key file of {name}")
        kdf = data["kdf"]
        if kdf["name"] != "scrypt" or data["cipher"]["name"] != "AES-256-GCM":
            raise SignoffError(f"{path}: unknown key protection {kdf['name']}")
        params = KdfParams(int(kdf["n"]), int(kdf["r"]), int(kdf["p"]))
        salt = _unb64(kdf["salt"], "the salt", path)
        nonce = _unb64(data["cipher"]["nonce"], "the nonce", path)
        sealed = _unb64(data["encrypted_private_key"], "the private key", path)
        public = str(data["public_key"])
    except (KeyError, TypeError, ValueError) as exc:
        if isinstance(exc, SignoffError):
            raise
        raise SignoffError(f"{path}: damaged key file ({exc})") from None
    try:
        raw = AESGCM(_derive(passphrase, salt, params)).decrypt(nonce, sealed, _aad(name, public))
    except InvalidTag:
        raise WrongPassphrase(f"wrong passphrase for {name}") from None
    return Instructor(name, Ed25519PrivateKey.from_private_bytes(raw))


# records


@dataclass(frozen=True)
class Evidence:
    """What a sign-off rests on: the run record (path and SHA-256 of its bytes) and metrics."""

    run_record: str = ""
    digest: str = ""
    metrics: dict[str, Any] = field(default_factory=dict)

    @classmethod
    def of_progress(cls, progress: Any) -> Evidence:
        """The evidence of an exercise's checks (an ``ExerciseProgress``): the run record of
        the first passing objective that rests on one, and every objective's evidence with
        the digest of them all."""
        objectives = [
            {"kind": o.kind, "passed": o.passed, "evidence": o.evidence}
            for o in progress.objectives
        ]
        metrics = {"objectives": objectives, "evidence_digest": progress.evidence_digest()}
        for o in progress.objectives:
            record, sha = o.evidence.get("record"), o.evidence.get("record_sha256")
            if o.passed and record and sha:
                return cls(run_record=str(record), digest=sha, metrics=metrics)
        return cls(run_record="", digest=progress.evidence_digest(), metrics=metrics)


@dataclass(frozen=True)
class RecordFields:
    """What the caller knows when asking for a sign-off."""

    student: str
    lab: str
    exercise: str
    driver: str = ""
    partner: str = ""
    evidence: Evidence = field(default_factory=Evidence)
    objectives_passed: bool = False


@dataclass(frozen=True)
class SignoffRecord:
    """What an instructor signs: the fields, the evidence, and the record's place in the log
    (``seq`` and the hash of the record before it; ``seq`` is ``None`` for a legacy record)."""

    student: str
    partner: str
    driver: str
    lab: str
    exercise: str
    instructor: str
    signed_at: str
    note: str
    override: bool
    evidence: Evidence
    seq: int | None = None
    prev: str = ""

    def canonical(self) -> bytes:
        """The exact bytes that are signed: sorted-key compact JSON, UTF-8."""
        evidence = {
            "run_record": self.evidence.run_record,
            "digest": self.evidence.digest,
            "metrics": self.evidence.metrics,
        }
        return signlog.signed_payload(self.__dict__, evidence, self.seq, self.prev)

    def columns(self, signature: str) -> dict[str, Any]:
        return {
            "student": self.student,
            "partner": self.partner,
            "driver": self.driver,
            "lab": self.lab,
            "exercise": self.exercise,
            "instructor": self.instructor,
            "signed_at": self.signed_at,
            "note": self.note,
            "override": self.override,
            "run_record": self.evidence.run_record,
            "evidence_digest": self.evidence.digest,
            "metrics": canonical_json(self.evidence.metrics),
            "signature": signature,
        }


def canonical_json(value: Any) -> str:
    try:
        return signlog.canonical_json(value)
    except (TypeError, ValueError) as exc:
        raise SignoffError(f"the evidence cannot be recorded: {exc}") from None


def record_digest(path: str | os.PathLike) -> str:
    """The evidence digest of a run record: ``sha256:`` and the hex SHA-256 of its bytes."""
    try:
        return f"sha256:{file_sha256(path)}"
    except OSError as exc:
        raise SignoffError(f"{path}: cannot read the run record: {exc.strerror}") from None


def record_from_stored(row: StoredSignoff) -> SignoffRecord:
    return SignoffRecord(
        student=row.student,
        partner=row.partner,
        driver=row.driver,
        lab=row.lab,
        exercise=row.exercise,
        instructor=row.instructor,
        signed_at=row.signed_at,
        note=row.note,
        override=row.override,
        evidence=Evidence(row.run_record, row.evidence_digest, row.metrics_value()),
        seq=None if row.legacy else row.seq,
        prev="" if row.legacy else row.prev_hash,
    )


def _check_fields(fields: RecordFields) -> Evidence:
    for label, value in (
        ("student", fields.student),
        ("lab", fields.lab),
        ("exercise", fields.exercise),
    ):
        if not value.strip():
            raise SignoffError(f"the {label} is missing")
    for problem in _name_problems(fields.student, fields.partner):
        raise SignoffError(problem)
    people = {fields.student, fields.partner} - {""}
    if fields.driver and fields.driver not in people:
        raise SignoffError(f"the driver {fields.driver} is neither the student nor the partner")
    ev = fields.evidence
    if not isinstance(ev.metrics, dict):
        raise SignoffError("the evidence metrics must be a mapping")
    metrics = json.loads(canonical_json(ev.metrics))
    digest = ev.digest
    if ev.run_record:
        actual = record_digest(ev.run_record)
        expected = digest if not digest or digest.startswith("sha256:") else f"sha256:{digest}"
        if expected and expected != actual:
            raise SignoffError(
                f"{ev.run_record}: the run record changed since it was checked "
                f"(digest {actual}, expected {expected})"
            )
        digest = actual
    return Evidence(str(ev.run_record), digest, metrics)


def sign_off(
    store: Store,
    instructor: str,
    passphrase: str,
    record_fields: RecordFields,
    override: bool = False,
    note: str = "",
    *,
    clock: Callable[[], datetime] = _now,
) -> tuple[int, SignoffRecord]:
    """Sign and store a record; returns its id and the record.

    Allowed when ``record_fields.objectives_passed`` or with ``override`` (which needs a note).
    Raises :class:`LockedOut` while locked, :class:`WrongPassphrase` (counted: the fifth in a
    row locks this instructor for a minute), :class:`UnknownInstructor`, or
    :class:`SignoffError`.
    """
    note = note.strip()
    if not record_fields.objectives_passed and not override:
        raise SignoffError("the objectives have not all passed: sign off with an override")
    if override and not note:
        raise SignoffError("an override needs a note saying why")
    evidence = _check_fields(record_fields)
    now = clock()
    state = store.lockout(instructor)
    if state.locked_until > now.timestamp():
        raise LockedOut(instructor, state.locked_until - now.timestamp())
    try:
        signer = unlock_instructor(store.data_dir, instructor, passphrase, store)
    except WrongPassphrase:
        after = store.record_failure(instructor, now, FAILURE_LIMIT, LOCK_SECONDS)
        where = f"{record_fields.student} {record_fields.lab}/{record_fields.exercise}"
        store.log_event(instructor, "wrong-passphrase", where, now)
        log.info("wrong passphrase for instructor %s at %s", instructor, where)
        if after.locked_until:
            store.log_event(instructor, "locked", f"for {LOCK_SECONDS:g} s", now)
            log.info("sign-off by %s locked for %g s", instructor, LOCK_SECONDS)
            raise LockedOut(instructor, LOCK_SECONDS) from None
        raise
    if state.failures:
        store.clear_failures(instructor, now)
    record = SignoffRecord(
        student=record_fields.student,
        partner=record_fields.partner,
        driver=record_fields.driver,
        lab=record_fields.lab,
        exercise=record_fields.exercise,
        instructor=instructor,
        signed_at=utc_iso(now),
        note=note,
        override=override,
        evidence=evidence,
    )

    def sign_at(seq: int, prev: str) -> dict[str, Any]:
        placed = replace(record, seq=seq, prev=prev)
        return placed.columns(signer.sign(placed.canonical()))

    stored = store.append_signoff(sign_at)
    return stored.id, replace(record, seq=stored.seq, prev=stored.prev_hash)


# verification


def _name_problems(student: str, partner: str) -> list[str]:
    """Why the names of a record's students are not ones the workbench accepts, if they are
    not: look-alike, invisible or not normalised."""
    problems = []
    for what, value in (("student", student), ("partner", partner)):
        if not value:
            continue
        try:
            clean = check_student(value, what)
        except NameProblem as exc:
            problems.append(f"{exc} ({value!r})")
            continue
        if clean != value:
            problems.append(f"the {what}'s name {value!r} is not in normal form ({clean!r})")
    return problems


@dataclass(frozen=True)
class Verdict:
    row: StoredSignoff
    problems: tuple[str, ...]
    notes: tuple[str, ...]

    @property
    def ok(self) -> bool:
        return not self.problems


@dataclass(frozen=True)
class LogVerdict:
    """The log checked as a whole: its head, breaks in the chain (records missing, a head
    the instructor kept that the log no longer holds) and each record's verdict."""

    head: Head
    breaks: tuple[str, ...]
    verdicts: tuple[Verdict, ...]
    legacy: int

    @property
    def ok(self) -> bool:
        return not self.breaks and all(v.ok for v in self.verdicts)

    def verified_rows(self) -> list[StoredSignoff]:
        return [v.row for v in self.verdicts if v.ok]


def _signature_problem(
    row: StoredSignoff,
    roster: dict[str, RosterEntry],
    local: dict[str, RosterEntry] | None,
) -> str | None:
    entry = roster.get(row.instructor)
    if entry is None:
        return f"instructor {row.instructor!r} is not in the trusted roster"
    if _signed_by(row, entry):
        return None
    other = (local or {}).get(row.instructor)
    if other is not None and other.public_key != entry.public_key and _signed_by(row, other):
        return (
            f"signed with a key the data folder's roster gives for {row.instructor} "
            f"({other.fingerprint()}), not the trusted one ({entry.fingerprint()}): the "
            "instructor was re-keyed in the data folder"
        )
    return (
        f"the signature does not match the record (changed after signing, or not signed by "
        f"{row.instructor}'s key in the trusted roster)"
    )


def _signed_by(row: StoredSignoff, entry: RosterEntry) -> bool:
    try:
        signature = base64.b64decode(row.signature, validate=True)
        entry.key().verify(signature, row.signed_bytes())
    except (InvalidSignature, binascii.Error, ValueError):
        return False
    return True


def verify_row(
    row: StoredSignoff,
    roster: dict[str, RosterEntry],
    local: dict[str, RosterEntry] | None = None,
) -> Verdict:
    """Check one stored record: its signature by the trusted roster's key, its students'
    names, and its run record if present (its place in the log is checked by
    :func:`verify_log`). ``local`` is the data folder's roster, used only to explain a
    signature by a key that is not the trusted one."""
    problems: list[str] = []
    notes: list[str] = []
    signature = _signature_problem(row, roster, local)
    if signature:
        problems.append(signature)
    problems.extend(_name_problems(row.student, row.partner))
    if row.legacy:
        notes.append(
            "legacy record (signed before the log was chained): its signature covers its "
            "fields, its place in the log was given when the database was upgraded"
        )
    if row.run_record:
        if os.path.exists(row.run_record):
            try:
                actual = record_digest(row.run_record)
            except SignoffError as exc:
                problems.append(str(exc))
            else:
                if actual != row.evidence_digest:
                    problems.append(
                        f"the run record {row.run_record} no longer has the signed digest"
                    )
        else:
            notes.append(f"run record {row.run_record} not present: its digest was not checked")
    return Verdict(row, tuple(problems), tuple(notes))


def _entry(row: StoredSignoff) -> signlog.Entry:
    return signlog.Entry(
        id=row.id,
        seq=row.seq,
        prev=row.prev_hash,
        stored_hash=row.entry_hash,
        legacy=row.legacy,
        signed=row.signed_bytes(),
        signature=row.signature,
    )


def verify_log(
    rows: list[StoredSignoff],
    roster: dict[str, RosterEntry],
    kept: Head | None = None,
    local: dict[str, RosterEntry] | None = None,
) -> LogVerdict:
    """Check the whole log (``rows`` in the order of the log): every record and the chain
    that links them, and, given the head the instructor kept, that the log still holds it."""
    chain = signlog.check_chain([_entry(r) for r in rows], kept)
    verdicts = []
    for row in rows:
        own = verify_row(row, roster, local)
        linked = chain.by_row.get(row.id, ())
        verdicts.append(replace(own, problems=(*linked, *own.problems)))
    legacy = sum(1 for r in rows if r.legacy)
    return LogVerdict(chain.head, chain.breaks, tuple(verdicts), legacy)


def verify_all(store: Store, roster: dict[str, RosterEntry]) -> list[Verdict]:
    """Every record of an open store, checked with its place in the log."""
    return list(verify_log(store.signoffs(), roster).verdicts)


def head_from_gradebook(path: Path) -> Head:
    """The log head kept in an exported gradebook (its ``log_head`` column)."""
    try:
        with path.open(encoding="utf-8", newline="") as fh:
            heads = {row.get("log_head") or "" for row in csv.DictReader(fh)}
    except OSError as exc:
        raise SignoffError(f"{path}: cannot read the gradebook: {exc.strerror}") from None
    except (csv.Error, UnicodeDecodeError) as exc:
        raise SignoffError(f"{path}: not a gradebook CSV ({exc})") from None
    heads.discard("")
    if len(heads) != 1:
        found = "no log_head column" if not heads else "different log heads in its rows"
        raise SignoffError(
            f"{path}: {found}; give the head itself with --head SEQ:HASH (as 'workbench "
            "signoff verify' or 'export' printed it)"
        )
    try:
        return Head.parse(heads.pop(), f"{path}: the log head")
    except LogError as exc:
        raise SignoffError(str(exc)) from None


def gradebook_rows(rows: list[StoredSignoff], head: Head) -> list[dict[str, str]]:
    """One row per student and exercise (each member of a pair gets one); the latest wins.
    Every row carries the record's place in the log and the log's head at export."""
    latest: dict[tuple[str, str, str], dict[str, str]] = {}
    for row in rows:
        for person, other in ((row.student, row.partner), (row.partner, row.student)):
            if not person:
                continue
            latest[(person, row.lab, row.exercise)] = {
                "student": person,
                "partner": other,
                "lab": row.lab,
                "exercise": row.exercise,
                "signed_at": row.signed_at,
                "instructor": row.instructor,
                "driver": row.driver,
                "override": "yes" if row.override else "no",
                "note": row.note,
                "evidence_digest": row.evidence_digest,
                "seq": "" if row.seq is None else str(row.seq),
                "log_head": str(head),
            }
    return [latest[k] for k in sorted(latest)]


GRADEBOOK_COLUMNS = (
    "student",
    "partner",
    "lab",
    "exercise",
    "signed_at",
    "instructor",
    "driver",
    "override",
    "note",
    "evidence_digest",
    "seq",
    "log_head",
)


def log_head(rows: list[StoredSignoff]) -> Head:
    """The head of a log as stored (``rows`` in the order of the log), checked or not."""
    return signlog.check_chain([_entry(r) for r in rows]).head
