"""The problems of signing off and checking sign-offs, each with a message meant for the user.

Every one is a :class:`SignoffError`, so a caller that only reports the problem catches that;
the others let a caller tell a wrong passphrase or a lock from the rest.
"""

from __future__ import annotations

import math


class SignoffError(ValueError):
    """A sign-off, key or roster problem, with a message meant for the user."""


class PassphraseTooShort(SignoffError):
    pass


class WrongPassphrase(SignoffError):
    pass


class LockedOut(SignoffError):
    """Signing by this instructor is refused for ``seconds`` more after ``limit`` wrong
    passphrases in a row."""

    def __init__(self, instructor: str, seconds: float, limit: int):
        self.seconds = seconds
        super().__init__(
            f"sign-off by {instructor} is locked for {math.ceil(seconds)} s more after "
            f"{limit} wrong passphrases"
        )


class UnknownInstructor(SignoffError):
    pass


class UntrustedRoster(SignoffError):
    """No roster that students cannot write was found or given."""
