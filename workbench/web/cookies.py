"""The logins of browsers: random ids given to browsers, kept on the server only as their
digests, each with its user, its expiry and the CSRF token its forms carry.

A login's id is 32 random bytes (``secrets``), sent to the browser in a cookie that is
``HttpOnly`` and ``SameSite=Strict`` (and ``Secure`` over https) and lives as long as the
login; the server keeps the logins it gave, so a forged or old cookie names nothing. A
logged-out browser gets a CSRF token of its own in a second cookie, which the login form must
send back (the double-submit rule); a logged-in browser's forms carry its login's token, made
from the id (so only the id's holder and the server can make it).

With a folder (``<data-dir>/web-logins``) every login is also a small file there, named by the
SHA-256 of its id and holding its user, how they logged in and when it expires (never the id
itself), so a restarted server (or another served from the same data folder) knows the
logins given before: a lab does not log in again because its server was restarted. Someone
who reads the folder learns who is logged in, not a cookie that would log them in. Expired
files are removed as the server starts and whenever one is read; a logout removes its file.
"""

from __future__ import annotations

import base64
import contextlib
import hashlib
import hmac
import json
import os
import secrets
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from workbench.files.atomic import write_text_atomic

SESSION_COOKIE = "workbench_login"
CSRF_COOKIE = "workbench_form"
#: logins kept at most; past it the oldest is forgotten (its browser logs in again)
MAX_LOGINS = 20_000
#: the longest a cookie value is read (a forged megabyte of cookie is not looked up)
MAX_COOKIE = 128
#: the folder of the data folder the logins are kept in
LOGINS_FOLDER = "web-logins"
#: the largest a login's file is read
MAX_LOGIN_FILE = 4096

Clock = Callable[[], float]


def new_token() -> str:
    return secrets.token_urlsafe(32)


def digest(login_id: str) -> str:
    """The name a login is kept under: its id's SHA-256, in hex."""
    return hashlib.sha256(login_id.encode()).hexdigest()


def form_token(login_id: str) -> str:
    """The CSRF token of a login's pages, made from its id."""
    made = hmac.new(login_id.encode(), b"workbench form token", hashlib.sha256).digest()
    return base64.urlsafe_b64encode(made).decode().rstrip("=")


def same_token(given: str | None, expected: str) -> bool:
    """Whether a token sent back is the one given (compared in constant time)."""
    if not given or not expected or len(given) > MAX_COOKIE:
        return False
    return hmac.compare_digest(given.encode(), expected.encode())


@dataclass
class Login:
    user: str
    role: str
    #: the form token of this login's pages
    csrf: str
    expires: float
    #: how the user logged in: "password" or the trusted header's name
    how: str


class Logins:
    """The logins given, by their ids' digests; kept in ``folder`` too when given (see the
    module)."""

    def __init__(
        self, lifetime: float, clock: Clock = time.time, folder: Path | None = None
    ) -> None:
        self.lifetime = lifetime
        self._clock = clock
        self._logins: dict[str, Login] = {}
        self.folder = folder
        if folder is not None:
            folder.mkdir(mode=0o700, parents=True, exist_ok=True)
            self._load()

    def open(self, user: str, role: str, how: str) -> tuple[str, Login]:
        """A new login for ``user``: its id (the cookie's value) and the login."""
        if len(self._logins) >= MAX_LOGINS:
            self._sweep()
            while len(self._logins) >= MAX_LOGINS:
                self._forget(next(iter(self._logins)))
        login_id = new_token()
        login = Login(user, role, form_token(login_id), self._clock() + self.lifetime, how)
        key = digest(login_id)
        self._logins[key] = login
        if self.folder is not None:
            said = {"user": user, "role": role, "how": how, "expires": login.expires}
            write_text_atomic(self.folder / key, json.dumps(said) + "\n", mode=0o600)
        return login_id, login

    def get(self, login_id: str | None) -> Login | None:
        """The login a cookie names; None for none, a forged one or one expired."""
        if not login_id or len(login_id) > MAX_COOKIE:
            return None
        key = digest(login_id)
        login = self._logins.get(key)
        if self.folder is not None:
            kept = self._read(key)
            if kept is None:  # logged out (perhaps on another server), or never given
                self._logins.pop(key, None)
                return None
            if login is None:  # given before a restart, or by another server
                login = self._logins[key] = Login(
                    kept.user, kept.role, form_token(login_id), kept.expires, kept.how
                )
            login.expires = kept.expires  # the folder's word is the one every server reads
        if login is None:
            return None
        if login.expires <= self._clock():
            self._forget(key)
            return None
        if not login.csrf:  # read from the folder as the server started
            login.csrf = form_token(login_id)
        return login

    def close(self, login_id: str | None) -> None:
        if login_id and len(login_id) <= MAX_COOKIE:
            self._forget(digest(login_id))

    def close_user(self, user: str) -> None:
        for key in [k for k, login in self._logins.items() if login.user == user]:
            self._forget(key)

    def __len__(self) -> int:
        return len(self._logins)

    def _forget(self, key: str) -> None:
        self._logins.pop(key, None)
        if self.folder is not None:
            with contextlib.suppress(OSError):
                (self.folder / key).unlink()

    def _sweep(self) -> None:
        now = self._clock()
        for key in [k for k, login in self._logins.items() if login.expires <= now]:
            self._forget(key)

    def _read(self, key: str) -> Login | None:
        """The login kept in the folder under ``key`` (its csrf is the caller's to make);
        None for none, or a file that is not a login's (removed)."""
        assert self.folder is not None
        path = self.folder / key
        try:
            with open(path, "rb") as file:
                data = json.loads(file.read(MAX_LOGIN_FILE))
            login = Login(
                str(data["user"]), str(data["role"]), "", float(data["expires"]),
                str(data["how"]),
            )  # fmt: skip
        except FileNotFoundError:
            return None
        except (OSError, ValueError, KeyError, TypeError):
            with contextlib.suppress(OSError):
                path.unlink()
            return None
        return login

    def _load(self) -> None:
        """Take the logins kept in the folder; remove the expired ones."""
        assert self.folder is not None
        now = self._clock()
        kept = []
        for entry in os.scandir(self.folder):
            if len(entry.name) != 64 or entry.name.startswith("."):
                continue
            login = self._read(entry.name)
            if login is None:
                continue
            if login.expires <= now:
                self._forget(entry.name)
            else:
                kept.append((login.expires, entry.name, login))
        for _, key, login in sorted(kept)[-MAX_LOGINS:]:
            self._logins[key] = login
