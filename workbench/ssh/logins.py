"""Who may try to log in, and how fast: the lab server's defence against password guessing
and against connections that never log in.

Plain bookkeeping with an injectable clock; the server does the waiting. Three rules:

- every failed password counts against the **account** tried and the **address** it came from;
  a success only clears the failures of the account that succeeded, so a student cannot wipe
  the count of guesses at an instructor's password with their own logins;
- a failed password is answered after a delay that doubles with the account's failures (and
  with the address's, past a small allowance for a lab behind one address), up to a maximum;
  after ``lock_after`` failures the account takes no passwords for ``lock_for`` seconds (its
  keys still work);
- connections that have not logged in are capped in all and per address, and so are the
  password attempts waiting out a delay, so neither can pile up.
"""

from __future__ import annotations

import time
from collections import Counter
from collections.abc import Callable
from dataclasses import dataclass

Clock = Callable[[], float]


@dataclass(frozen=True)
class LoginPolicy:
    """The numbers behind the rules (the defaults are the documented ones)."""

    first_delay: float = 0.5
    max_delay: float = 8.0
    #: failures are forgotten after this long without a new one
    quiet: float = 600.0
    #: failures from one address before the address itself is slowed down
    address_allowance: int = 3
    lock_after: int = 10
    lock_for: float = 900.0
    #: password attempts waiting out a delay at once, in all and from one address
    max_waiting: int = 32
    max_waiting_per_address: int = 4
    #: connections that have not logged in yet, in all and from one address
    max_unauthenticated: int = 100
    max_unauthenticated_per_address: int = 10
    #: seconds a connection has to log in
    login_timeout: float = 30.0

    def delay_after(self, failures: int) -> float:
        if failures <= 0:
            return 0.0
        return min(self.first_delay * 2 ** min(failures - 1, 60), self.max_delay)


@dataclass
class _Failures:
    count: int
    last: float


class _FailureCounts:
    """Failures per key (an account or an address), forgotten after a quiet period."""

    LIMIT = 10_000  # keys kept before the quiet ones are swept out

    def __init__(self, quiet: float, clock: Clock) -> None:
        self.quiet = quiet
        self._clock = clock
        self._counts: dict[str, _Failures] = {}

    def get(self, key: str) -> int:
        entry = self._counts.get(key)
        if entry is None:
            return 0
        if self._clock() - entry.last >= self.quiet:
            del self._counts[key]
            return 0
        return entry.count

    def add(self, key: str) -> int:
        now = self._clock()
        count = self.get(key) + 1
        self._counts[key] = _Failures(count, now)
        if len(self._counts) > self.LIMIT:
            for old in [k for k, e in self._counts.items() if now - e.last >= self.quiet]:
                del self._counts[old]
        return count

    def clear(self, key: str) -> None:
        self._counts.pop(key, None)


class LoginGuard:
    """Failed logins per account and per address, the delays they earn and account locks."""

    def __init__(self, policy: LoginPolicy | None = None, clock: Clock = time.monotonic) -> None:
        self.policy = policy or LoginPolicy()
        self._clock = clock
        self._accounts = _FailureCounts(self.policy.quiet, clock)
        self._addresses = _FailureCounts(self.policy.quiet, clock)
        self._locked_until: dict[str, float] = {}

    def account_failures(self, account: str) -> int:
        return self._accounts.get(account)

    def address_failures(self, address: str) -> int:
        return self._addresses.get(address)

    def delay(self, account: str, address: str) -> float:
        """Seconds to wait before checking a password for ``account`` from ``address``."""
        policy = self.policy
        by_account = policy.delay_after(self._accounts.get(account))
        by_address = policy.delay_after(self._addresses.get(address) - policy.address_allowance)
        return max(by_account, by_address)

    def locked_for(self, account: str) -> float:
        """Seconds left of the account's password lock (0 when passwords are taken)."""
        until = self._locked_until.get(account)
        if until is None:
            return 0.0
        left = until - self._clock()
        if left <= 0:
            del self._locked_until[account]
            self._accounts.clear(account)
            return 0.0
        return left

    def password_failed(self, account: str, address: str) -> bool:
        """Count a wrong password; True when this failure locks the account's passwords."""
        self._addresses.add(address)
        if self.locked_for(account):
            return False
        count = self._accounts.add(account)
        if count >= self.policy.lock_after:
            self._locked_until[account] = self._clock() + self.policy.lock_for
            return True
        return False

    def key_failed(self, address: str) -> None:
        """A connection that offered only keys the account does not hold (counts the address)."""
        self._addresses.add(address)

    def password_succeeded(self, account: str) -> None:
        """The right password: that account's failures are forgotten, nothing else."""
        self._accounts.clear(account)


class ConnectionGate:
    """Caps on connections not logged in yet and on password attempts waiting out a delay."""

    def __init__(self, policy: LoginPolicy) -> None:
        self.policy = policy
        self.unauthenticated: Counter[str] = Counter()
        self.waiting: Counter[str] = Counter()

    def refuse_connection(self, address: str) -> str | None:
        """Why a new connection from ``address`` is closed at once, or None to let it in."""
        policy = self.policy
        if self.unauthenticated[address] >= policy.max_unauthenticated_per_address:
            return (
                f"{policy.max_unauthenticated_per_address} connections from this address "
                "have not logged in yet"
            )
        if self.unauthenticated.total() >= policy.max_unauthenticated:
            return f"{policy.max_unauthenticated} connections have not logged in yet"
        return None

    def opened(self, address: str) -> None:
        self.unauthenticated[address] += 1

    def settled(self, address: str) -> None:
        """The connection logged in or went away: it no longer counts as waiting to log in."""
        self.unauthenticated[address] -= 1
        if self.unauthenticated[address] <= 0:
            del self.unauthenticated[address]

    def start_waiting(self, address: str) -> bool:
        """Take a place for a password attempt to wait in; False when none is free."""
        policy = self.policy
        if (
            self.waiting[address] >= policy.max_waiting_per_address
            or self.waiting.total() >= policy.max_waiting
        ):
            return False
        self.waiting[address] += 1
        return True

    def stop_waiting(self, address: str) -> None:
        self.waiting[address] -= 1
        if self.waiting[address] <= 0:
            del self.waiting[address]


class QuietLog:
    """Say a repeated event once per ``every`` seconds and key, with how many went unsaid."""

    def __init__(self, every: float = 10.0, clock: Clock = time.monotonic) -> None:
        self.every = every
        self._clock = clock
        self._last: dict[str, tuple[float, int]] = {}

    def due(self, key: str) -> int | None:
        """None to stay quiet; else how many were held back since it was last said."""
        now = self._clock()
        last = self._last.get(key)
        if last is not None and now - last[0] < self.every:
            self._last[key] = (last[0], last[1] + 1)
            return None
        self._last[key] = (now, 0)
        if len(self._last) > 10_000:
            self._last = {k: v for k, v in self._last.items() if now - v[0] < self.every}
        return last[1] if last is not None else 0
