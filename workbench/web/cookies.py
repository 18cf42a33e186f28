"""The logins of browsers: random ids kept on the server, each with its user, its expiry and
the CSRF token its forms carry.

A login's id is 32 random bytes (``secrets``), sent to the browser in a cookie that is
``HttpOnly`` and ``SameSite=Strict`` (and ``Secure`` over https) and lives as long as the
login; the server keeps the logins it gave, so a forged or old cookie names nothing. A
logged-out browser gets a CSRF token of its own in a second cookie, which the login form must
send back (the double-submit rule); a logged-in browser's forms carry its login's token.
"""

from __future__ import annotations

import hmac
import secrets
import time
from collections.abc import Callable
from dataclasses import dataclass

SESSION_COOKIE = "workbench_login"
CSRF_COOKIE = "workbench_form"
#: logins kept at most; past it the oldest is forgotten (its browser logs in again)
MAX_LOGINS = 20_000
#: the longest a cookie value is read (a forged megabyte of cookie is not looked up)
MAX_COOKIE = 128

Clock = Callable[[], float]


def new_token() -> str:
    return secrets.token_urlsafe(32)


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
    """The logins given, by id."""

    def __init__(self, lifetime: float, clock: Clock = time.time) -> None:
        self.lifetime = lifetime
        self._clock = clock
        self._logins: dict[str, Login] = {}

    def open(self, user: str, role: str, how: str) -> tuple[str, Login]:
        """A new login for ``user``: its id (the cookie's value) and the login."""
        if len(self._logins) >= MAX_LOGINS:
            self._sweep()
            while len(self._logins) >= MAX_LOGINS:
                del self._logins[next(iter(self._logins))]
        login_id = new_token()
        login = Login(user, role, new_token(), self._clock() + self.lifetime, how)
        self._logins[login_id] = login
        return login_id, login

    def get(self, login_id: str | None) -> Login | None:
        """The login a cookie names; None for none, a forged one or one expired."""
        if not login_id or len(login_id) > MAX_COOKIE:
            return None
        login = self._logins.get(login_id)
        if login is None:
            return None
        if login.expires <= self._clock():
            del self._logins[login_id]
            return None
        return login

    def close(self, login_id: str | None) -> None:
        if login_id:
            self._logins.pop(login_id, None)

    def close_user(self, user: str) -> None:
        for login_id in [i for i, login in self._logins.items() if login.user == user]:
            del self._logins[login_id]

    def __len__(self) -> int:
        return len(self._logins)

    def _sweep(self) -> None:
        now = self._clock()
        for login_id in [i for i, login in self._logins.items() if login.expires <= now]:
            del self._logins[login_id]
