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
- connections that have not logged in are capped in all and per source (an IPv4 address, an
  IPv6 /64, see :mod:`.sources`), and so are the password attempts waiting out a delay, so
  neither can pile up; past a start threshold new connections are dropped at random, more
  often the fuller it is (as OpenSSH's MaxStartups), and a source whose connections hold
  places without logging in is refused for a while (its penalty).
"""

from __future__ import annotations

import random
import time
from collections import Counter
from collections.abc import Callable
from dataclasses import dataclass

from .sources import Penalties, source_of

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
    #: connections that have not logged in yet, in all and from one source
    max_unauthenticated: int = 100
    max_unauthenticated_per_address: int = 10
    #: from this many connections not logged in, a new one is dropped at random: with
    #: ``start_drop`` chance at first, rising evenly to certainty at ``max_unauthenticated``
    unauthenticated_start: int = 50
    start_drop: float = 0.3
    #: a source is refused once its connections that went without logging in held places for
    #: ``penalty_least`` seconds more than time has paid back; for at most ``penalty_longest``
    #: seconds (0: no penalties)
    penalty_least: float = 90.0
    penalty_longest: float = 600.0
    #: seconds a connection has to log in
    login_timeout: float = 30.0
    #: the random early drop's seed (None: from the system)
    seed: int | None = None

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
    """Caps on connections not logged in yet and on password attempts waiting out a delay.

    Connections are counted by source (:func:`.sources.source_of`), password attempts by
    address."""

    def __init__(self, policy: LoginPolicy, clock: Clock = time.monotonic) -> None:
        self.policy = policy
        self.unauthenticated: Counter[str] = Counter()
        self.waiting: Counter[str] = Counter()
        self.penalties = Penalties(policy.penalty_least, policy.penalty_longest, clock)
        self._random = random.Random(policy.seed)

    def refuse_connection(self, address: str) -> str | None:
        """Why a new connection from ``address`` is closed at once, or None to let it in."""
        policy = self.policy
        source = source_of(address)
        penalty = self.penalties.refused_for(source)
        if penalty:
            return (
                f"refused for another {penalty:.0f} s: connections from {source} held places "
                "at the login without logging in"
            )
        if self.unauthenticated[source] >= policy.max_unauthenticated_per_address:
            where = "this address" if source == address else source
            return (
                f"{policy.max_unauthenticated_per_address} connections from {where} "
                "have not logged in yet"
            )
        waiting = self.unauthenticated.total()
        if waiting >= policy.max_unauthenticated:
            return f"{policy.max_unauthenticated} connections have not logged in yet"
        start = policy.unauthenticated_start
        if waiting >= start:
            share = (waiting - start) / (policy.max_unauthenticated - start)
            chance = policy.start_drop + (1 - policy.start_drop) * share
            if self._random.random() < chance:
                return f"dropped at random: {waiting} connections have not logged in yet"
        return None

    def opened(self, address: str) -> None:
        self.unauthenticated[source_of(address)] += 1

    def settled(self, address: str, held: float = 0.0, logged_in: bool = True) -> bool:
        """The connection logged in or went away after ``held`` seconds: it no longer counts
        as waiting to log in; one that went without logging in is charged to its source.
        True when that starts the source's penalty."""
        source = source_of(address)
        self.unauthenticated[source] -= 1
        if self.unauthenticated[source] <= 0:
            del self.unauthenticated[source]
        return not logged_in and self.penalties.charge(source, held)

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
