"""Password hashes for SSH logins: scrypt in a self-describing string.

``scrypt$N$r$p$SALT$HASH`` with the salt and hash in unpadded URL-safe base64, so the cost
can be raised later without breaking the hashes already written.
"""

from __future__ import annotations

import base64
import hashlib
import hmac
import os

MIN_PASSWORD = 8
SCHEME = "scrypt"
N, R, P = 2**14, 8, 1
SALT_BYTES = 16
HASH_BYTES = 32
#: refuse hashes whose cost would take seconds or gigabytes to check
MAX_N, MAX_R, MAX_P = 2**20, 32, 16


class PasswordError(ValueError):
    """A password that cannot be used, or a hash string that cannot be read."""


def _b64(raw: bytes) -> str:
    return base64.urlsafe_b64encode(raw).rstrip(b"=").decode()


def _unb64(text: str) -> bytes:
    return base64.urlsafe_b64decode(text + "=" * (-len(text) % 4))


def check_password(password: str) -> str:
    """The password itself when it is long enough; else :class:`PasswordError`."""
    if len(password) < MIN_PASSWORD:
        raise PasswordError(f"a password needs at least {MIN_PASSWORD} characters")
    if not password.isprintable():
        raise PasswordError("a password cannot have control characters")
    return password


def _derive(password: str, salt: bytes, n: int, r: int, p: int, size: int) -> bytes:
    return hashlib.scrypt(
        password.encode(), salt=salt, n=n, r=r, p=p, dklen=size, maxmem=256 * n * r + (1 << 20)
    )


def hash_password(password: str, *, n: int = N, r: int = R, p: int = P) -> str:
    """A new salted hash of ``password`` (checked for length first)."""
    check_password(password)
    salt = os.urandom(SALT_BYTES)
    digest = _derive(password, salt, n, r, p, HASH_BYTES)
    return f"{SCHEME}${n}${r}${p}${_b64(salt)}${_b64(digest)}"


def parse_hash(text: str) -> tuple[int, int, int, bytes, bytes]:
    """``(n, r, p, salt, hash)`` of a hash string; :class:`PasswordError` says what is wrong."""
    parts = text.split("$")
    if len(parts) != 6 or parts[0] != SCHEME:
        raise PasswordError(
            "not a password hash of the form scrypt$N$r$p$salt$hash "
            "(make one with: workbench ssh add-user NAME --password)"
        )
    try:
        n, r, p = (int(x) for x in parts[1:4])
        salt, digest = _unb64(parts[4]), _unb64(parts[5])
    except ValueError:
        raise PasswordError(
            "the password hash has a number or base64 field that cannot be read"
        ) from None
    if n < 2 or n & (n - 1) or n > MAX_N or not 0 < r <= MAX_R or not 0 < p <= MAX_P:
        raise PasswordError(f"the password hash has unusable scrypt costs N={n} r={r} p={p}")
    if len(salt) < 8 or len(digest) < 16:
        raise PasswordError("the password hash's salt or hash is too short")
    return n, r, p, salt, digest


def verify_password(password: str, hashed: str) -> bool:
    """Whether ``password`` matches ``hashed`` (compared in constant time)."""
    n, r, p, salt, digest = parse_hash(hashed)
    return hmac.compare_digest(_derive(password, salt, n, r, p, len(digest)), digest)
