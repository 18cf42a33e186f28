"""A password checked the way both doors check one: locks, the slow-down, one account's
checks in turn, a cap on attempts waiting, and an unknown name costing what a wrong password
costs.

The door says what it makes of the :class:`Verdict` (the SSH server's login log lines and
connection stages, the browser door's login page); the rules are :mod:`.logins`'.
"""

from __future__ import annotations

import asyncio
import contextlib
import logging
from collections import Counter
from collections.abc import AsyncIterator
from dataclasses import dataclass
from typing import Any

from .limits import describe_duration
from .logins import ConnectionGate, LoginGuard
from .passwords import hash_password, verify_password
from .users import User, UsersFile
from .workers import PASSWORDS, in_pool

log = logging.getLogger("workbench.ssh")

#: checked against when a user is unknown, so a wrong name costs the same time as a wrong password
_DUMMY_HASH = hash_password("not a real password")


@dataclass(frozen=True)
class Verdict:
    """What a password check found: the user let in, or why not."""

    user: User | None = None
    why: str = ""
    #: the password was checked (a costly refusal, logged each time); an unchecked refusal
    #: (a lock, too many waiting) costs nothing and is logged now and then
    checked: bool = True
    #: this failure locked the account's passwords
    locked: bool = False


class PasswordDesk:
    """Checks passwords against the users file under the login rules of ``guard`` and the
    waiting caps of ``gate``."""

    def __init__(self, users: UsersFile, guard: LoginGuard, gate: ConnectionGate[Any]) -> None:
        self.users = users
        self.guard = guard
        self.gate = gate
        #: password checks for one account take turns, so parallel guesses wait in line
        self._turns: dict[str, asyncio.Lock] = {}
        self._queue: Counter[str] = Counter()

    def known(self, username: str) -> User | None:
        user = self.users.get(username)
        if self.users.problem:
            log.error("users file not read again, the earlier users stay: %s", self.users.problem)
        return user

    @contextlib.asynccontextmanager
    async def account_turn(self, account: str) -> AsyncIterator[None]:
        """Wait for the account's turn to have a password checked."""
        lock = self._turns.setdefault(account, asyncio.Lock())
        self._queue[account] += 1
        try:
            async with lock:
                yield
        finally:
            self._queue[account] -= 1
            if not self._queue[account]:
                del self._queue[account], self._turns[account]

    async def check(self, username: str, password: str, address: str) -> Verdict:
        """Check ``password`` for ``username``, tried from ``address``."""
        if not self.gate.start_waiting(address):
            return Verdict(why="too many password attempts at once, not checked", checked=False)
        try:
            async with self.account_turn(username):
                return await self._check(username, password, address)
        finally:
            self.gate.stop_waiting(address)

    async def _check(self, username: str, password: str, address: str) -> Verdict:
        guard = self.guard
        locked = guard.locked_for(username)
        if locked:
            why = f"passwords locked for another {describe_duration(round(locked))}"
            return Verdict(why=why, checked=False)
        delay = guard.delay(username, address)
        if delay:
            await asyncio.sleep(delay)
        user = self.known(username)
        stored = user.password if user is not None and user.password else _DUMMY_HASH
        ok = await in_pool(PASSWORDS, verify_password, password, stored)
        if user is not None and ok and user.password:
            guard.password_succeeded(username)
            return Verdict(user)
        locks = guard.password_failed(username, address)
        return Verdict(why="unknown user" if user is None else "wrong password", locked=locks)

    def lock_words(self) -> str:
        policy = self.guard.policy
        return f"locked for {describe_duration(policy.lock_for)} after {policy.lock_after} failures"
