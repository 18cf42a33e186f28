"""Instructors' keys: making a key pair and unlocking it with the passphrase.

An instructor has an Ed25519 key pair. The public key joins the roster (:mod:`.roster`); the
private key is kept in the data folder (or, with PostgreSQL, the database), encrypted with
AES-256-GCM under a key derived from the instructor's passphrase by scrypt. Deriving that key
takes ~128 MiB and a fraction of a second: :meth:`SealedKey.unlock` is that step alone, so a
front end that must stay responsive can run it off its event loop.
"""

from __future__ import annotations

import json
import secrets
from dataclasses import dataclass, field
from datetime import UTC, datetime
from pathlib import Path

from cryptography.exceptions import InvalidTag
from cryptography.hazmat.primitives import serialization
from cryptography.hazmat.primitives.asymmetric.ed25519 import Ed25519PrivateKey
from cryptography.hazmat.primitives.ciphers.aead import AESGCM
from cryptography.hazmat.primitives.kdf.scrypt import Scrypt

from ..store.store import Store, utc_iso
from .roster import (
    RosterEntry,
    check_name,
    from_b64,
    key_path,
    load_roster,
    roster_keys,
    save_roster,
    to_b64,
)
from .signoff_errors import PassphraseTooShort, SignoffError, UnknownInstructor, WrongPassphrase

KEY_FORMAT = "workbench-instructor-key/1"
MIN_PASSPHRASE = 10


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


def check_passphrase(passphrase: str) -> None:
    if len(passphrase) < MIN_PASSPHRASE:
        raise PassphraseTooShort(
            f"the passphrase must be at least {MIN_PASSPHRASE} characters long "
            f"(it has {len(passphrase)})"
        )


@dataclass(frozen=True)
class Instructor:
    """An instructor whose private key has been unlocked with the passphrase."""

    name: str
    private_key: Ed25519PrivateKey = field(repr=False)

    def public_key_b64(self) -> str:
        raw = self.private_key.public_key().public_bytes(
            serialization.Encoding.Raw, serialization.PublicFormat.Raw
        )
        return to_b64(raw)

    def sign(self, data: bytes) -> str:
        return to_b64(self.private_key.sign(data))


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
    keys = roster_keys(store, data_dir)
    if name in keys.entries():
        raise SignoffError(f"{name} is already in the roster {keys.where}")
    kept = load_roster(trusted) if trusted is not None else {}
    if name in kept:
        raise SignoffError(
            f"{name} is already in your trusted roster {trusted} with another key: choose "
            "another name, or remove the old entry from that file first"
        )
    if keys.holds_key(name):
        raise SignoffError(f"{keys.key_text(name)[1]}: a key for {name} already exists")
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
        "kdf": {
            "name": "scrypt",
            "n": params.n,
            "r": params.r,
            "p": params.p,
            "salt": to_b64(salt),
        },
        "cipher": {"name": "AES-256-GCM", "nonce": to_b64(nonce)},
        "encrypted_private_key": to_b64(sealed),
    }
    entry = RosterEntry(name, public, utc_iso(now or datetime.now(UTC)))
    keys.add(entry, json.dumps(data, indent=2) + "\n")
    if trusted is not None:
        kept[name] = entry
        save_roster(trusted, kept)
    return entry


def copy_instructor(
    source_dir: Path,
    data_dir: Path,
    name: str,
    passphrase: str,
    trusted: Path,
    store: Store | None = None,
) -> RosterEntry:
    """Add an instructor already in the ``trusted`` roster to another data folder (or the
    course database of a PostgreSQL ``store``) with the same key: the sealed key of
    ``source_dir`` is copied as it is, once the passphrase opens it and it is the key the
    trusted roster holds, and the trusted entry joins that folder's roster."""
    name = check_name(name)
    entry = load_roster(trusted).get(name)
    if entry is None:
        raise SignoffError(f"{name} is not in your trusted roster {trusted}")
    keys = roster_keys(store, data_dir)
    if name in keys.entries():
        raise SignoffError(f"{name} is already in the roster {keys.where}")
    source = key_path(source_dir, name)
    try:
        text = source.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise UnknownInstructor(f"no key for instructor {name} in {source.parent}") from None
    except OSError as exc:
        raise SignoffError(f"{source}: cannot read the key: {exc.strerror}") from None
    sealed = parse_key(text, name, source)
    if sealed.public_key != entry.public_key:
        raise SignoffError(
            f"{source} holds another key for {name} than your trusted roster {trusted} "
            f"({entry.fingerprint()}): it is not copied"
        )
    if sealed.unlock(passphrase).public_key_b64() != entry.public_key:
        raise SignoffError(f"{source}: the key does not match its public key; it is not copied")
    if keys.holds_key(name):
        raise SignoffError(f"{keys.key_text(name)[1]}: a key for {name} already exists")
    keys.add(entry, text)
    return entry


@dataclass(frozen=True)
class SealedKey:
    """An instructor's private key as it is kept: encrypted under their passphrase."""

    name: str
    public_key: str
    params: KdfParams
    salt: bytes
    nonce: bytes
    sealed: bytes = field(repr=False)

    def unlock(self, passphrase: str) -> Instructor:
        """The instructor with their key decrypted; :class:`WrongPassphrase` if it does not
        open. This runs scrypt (the slow part of signing) and touches nothing but memory, so
        it may run in any thread."""
        key = _derive(passphrase, self.salt, self.params)
        try:
            raw = AESGCM(key).decrypt(self.nonce, self.sealed, _aad(self.name, self.public_key))
        except InvalidTag:
            raise WrongPassphrase(f"wrong passphrase for {self.name}") from None
        return Instructor(self.name, Ed25519PrivateKey.from_private_bytes(raw))


def read_key(data_dir: Path, name: str, store: Store | None = None) -> SealedKey:
    """An instructor's sealed private key, from the data folder or from the database of a
    PostgreSQL ``store``; :class:`UnknownInstructor` if there is none."""
    keys = roster_keys(store, data_dir)
    text, where = keys.key_text(name)
    if text is None:
        raise UnknownInstructor(
            f"no key for instructor {name} in {keys.keys_at} (create it with 'workbench "
            "instructor add')"
        )
    return parse_key(text, name, where)


def parse_key(text: str, name: str, path: Path | str) -> SealedKey:
    """The sealed key of ``name`` written in ``text`` (read from ``path``);
    :class:`SignoffError` naming the place when it is not that key file."""
    try:
        data = json.loads(text)
    except json.JSONDecodeError:
        raise SignoffError(f"{path}: the key file is not JSON") from None
    try:
        if data["format"] != KEY_FORMAT or data["name"] != name:
            raise SignoffError(f"{path}: not the key file of {name}")
        kdf = data["kdf"]
        if kdf["name"] != "scrypt" or data["cipher"]["name"] != "AES-256-GCM":
            raise SignoffError(f"{path}: unknown key protection {kdf['name']}")
        return SealedKey(
            name=name,
            public_key=str(data["public_key"]),
            params=KdfParams(int(kdf["n"]), int(kdf["r"]), int(kdf["p"])),
            salt=from_b64(kdf["salt"], "the salt", path),
            nonce=from_b64(data["cipher"]["nonce"], "the nonce", path),
            sealed=from_b64(data["encrypted_private_key"], "the private key", path),
        )
    except (KeyError, TypeError, ValueError) as exc:
        if isinstance(exc, SignoffError):
            raise
        raise SignoffError(f"{path}: damaged key file ({exc})") from None


def unlock_instructor(
    data_dir: Path, name: str, passphrase: str, store: Store | None = None
) -> Instructor:
    """Read an instructor's private key (see :func:`read_key`) and decrypt it;
    :class:`WrongPassphrase` if it does not open."""
    return read_key(data_dir, name, store).unlock(passphrase)
