"""Instructor keys and signed sign-off records.

An instructor has an Ed25519 key pair. The public key is listed in the roster (a JSON file that
anyone may copy and use to check records); the private key is kept in the data folder,
encrypted with AES-256-GCM under a key derived from the instructor's passphrase by scrypt.
A sign-off record is turned into canonical JSON bytes and signed; verifying rebuilds the same
bytes from the stored columns, so changing any of them breaks the signature.
"""

from __future__ import annotations

import base64
import binascii
import hashlib
import json
import logging
import math
import os
import re
import secrets
from collections.abc import Callable
from dataclasses import dataclass, field
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

from cryptography.exceptions import InvalidSignature, InvalidTag
from cryptography.hazmat.primitives import serialization
from cryptography.hazmat.primitives.asymmetric.ed25519 import Ed25519PrivateKey, Ed25519PublicKey
from cryptography.hazmat.primitives.ciphers.aead import AESGCM
from cryptography.hazmat.primitives.kdf.scrypt import Scrypt

from workbench.sim.mazefile import write_text_atomic
from workbench.sim.record import file_sha256

from .store import Store, StoredSignoff, utc_iso

log = logging.getLogger(__name__)

KEY_FORMAT = "workbench-instructor-key/1"
ROSTER_FORMAT = "workbench-roster/1"
RECORD_FORMAT = "workbench-signoff/1"
ROSTER_NAME = "roster.json"
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
    """An instructor's name as shown in records: 1-64 printable characters, no outer spaces."""
    if not name or not name.strip():
        raise SignoffError("the instructor's name is empty")
    if name != name.strip():
        raise SignoffError(f"the instructor's name {name!r} starts or ends with a space")
    if len(name) > MAX_NAME:
        raise SignoffError(f"the instructor's name is longer than {MAX_NAME} characters")
    if not name.isprintable():
        raise SignoffError(f"the instructor's name {name!r} has control characters")
    return name


def _slug(name: str) -> str:
    slug = re.sub(r"[^a-z0-9]+", "-", name.lower()).strip("-")
    digest = hashlib.sha256(name.encode("utf-8")).hexdigest()[:8]
    return f"{slug or 'instructor'}-{digest}"


def key_path(data_dir: Path, name: str) -> Path:
    return data_dir / KEYS_DIR / f"{_slug(name)}.key.json"


def roster_path(data_dir: Path) -> Path:
    return data_dir / ROSTER_NAME


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
        if item["name"] in roster:
            raise SignoffError(f"{path}: {item['name']} is listed twice")
        entry = RosterEntry(item["name"], item["public_key"], str(item.get("added", "")))
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
) -> RosterEntry:
    """Make a key pair: the private key is saved encrypted, the public key joins the roster."""
    check_name(name)
    check_passphrase(passphrase)
    params = kdf or KdfParams()
    roster_file = roster_path(data_dir)
    roster = load_roster(roster_file)
    if name in roster:
        raise SignoffError(f"{name} is already in the roster {roster_file}")
    target = key_path(data_dir, name)
    if target.exists():
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
    target.parent.mkdir(parents=True, exist_ok=True)
    fd = os.open(target, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o600)
    with os.fdopen(fd, "w", encoding="utf-8") as fh:
        fh.write(json.dumps(data, indent=2) + "\n")
        fh.flush()
        os.fsync(fh.fileno())
    entry = RosterEntry(name, public, utc_iso(now or _now()))
    roster[name] = entry
    save_roster(roster_file, roster)
    return entry


def unlock_instructor(data_dir: Path, name: str, passphrase: str) -> Instructor:
    """Decrypt an instructor's private key; :class:`WrongPassphrase` if it does not open."""
    path = key_path(data_dir, name)
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise UnknownInstructor(
            f"no key for instructor {name} in {path.parent} (create it with "
            f"'workbench instructor add')"
        ) from None
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

    def canonical(self) -> bytes:
        """The exact bytes that are signed: sorted-key compact JSON, UTF-8."""
        data = {
            "format": RECORD_FORMAT,
            "student": self.student,
            "partner": self.partner,
            "driver": self.driver,
            "lab": self.lab,
            "exercise": self.exercise,
            "instructor": self.instructor,
            "signed_at": self.signed_at,
            "note": self.note,
            "override": self.override,
            "evidence": {
                "run_record": self.evidence.run_record,
                "digest": self.evidence.digest,
                "metrics": self.evidence.metrics,
            },
        }
        return canonical_json(data).encode("utf-8")

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
        return json.dumps(
            value, sort_keys=True, separators=(",", ":"), ensure_ascii=False, allow_nan=False
        )
    except (TypeError, ValueError) as exc:
        raise SignoffError(f"the evidence cannot be recorded: {exc}") from None


def record_digest(path: str | os.PathLike) -> str:
    """The evidence digest of a run record: ``sha256:`` and the hex SHA-256 of its bytes."""
    try:
        return f"sha256:{file_sha256(path)}"
    except OSError as exc:
        raise SignoffError(f"{path}: cannot read the run record: {exc.strerror}") from None


def record_from_stored(row: StoredSignoff) -> SignoffRecord:
    try:
        metrics = json.loads(row.metrics)
    except json.JSONDecodeError:
        metrics = {"unreadable": row.metrics}
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
        evidence=Evidence(row.run_record, row.evidence_digest, metrics),
    )


def _check_fields(fields: RecordFields) -> Evidence:
    for label, value in (
        ("student", fields.student),
        ("lab", fields.lab),
        ("exercise", fields.exercise),
    ):
        if not value.strip():
            raise SignoffError(f"the {label} is missing")
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
        signer = unlock_instructor(store.data_dir, instructor, passphrase)
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
    signature = signer.sign(record.canonical())
    row_id = store.add_signoff(record.columns(signature))
    return row_id, record


# verification


@dataclass(frozen=True)
class Verdict:
    row: StoredSignoff
    problems: tuple[str, ...]
    notes: tuple[str, ...]

    @property
    def ok(self) -> bool:
        return not self.problems


def verify_row(row: StoredSignoff, roster: dict[str, RosterEntry]) -> Verdict:
    """Check a stored record: its signature by a roster key, and its run record if present."""
    problems: list[str] = []
    notes: list[str] = []
    entry = roster.get(row.instructor)
    if entry is None:
        problems.append(f"instructor {row.instructor!r} is not in the roster")
    else:
        record = record_from_stored(row)
        try:
            signature = base64.b64decode(row.signature, validate=True)
            entry.key().verify(signature, record.canonical())
        except (InvalidSignature, binascii.Error, ValueError):
            problems.append(
                f"the signature does not match the record (changed after signing, or not "
                f"signed by {row.instructor}'s key)"
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


def verify_all(store: Store, roster: dict[str, RosterEntry]) -> list[Verdict]:
    return [verify_row(row, roster) for row in store.signoffs()]


def verified_rows(store: Store, roster: dict[str, RosterEntry]) -> list[StoredSignoff]:
    return [v.row for v in verify_all(store, roster) if v.ok]


def gradebook_rows(rows: list[StoredSignoff]) -> list[dict[str, str]]:
    """One row per student and exercise (each member of a pair gets one); the latest wins."""
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
)
