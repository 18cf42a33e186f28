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
  often the fuller it is (as OpenSSH's MaxStartups), unless a connection that has sat on its
  place past a short grace makes room for them, and a source whose connections hold places
  without logging in is refused for a while (its penalty).
"""

from __future__ import annotations

import random
import time
from collections import Counter
from collections.abc import Callable, Hashable
from dataclasses import dataclass
from enum import IntEnum
from typing import Generic, TypeVar

from .sources import Penalties, source_of

Clock = Callable[[], float]
#: how the server knows a connection (its connection object)
Key = TypeVar("Key", bound=Hashable)


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
    #: seconds a connection not logged in keeps its place for sure; past them it makes room
    #: for a new connection that would find the places full or be dropped at random
    unauthenticated_grace: float = 5.0
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


class Stage(IntEnum):
    """How far a connection not logged in yet has come; the least advanced make room first."""

    #: it holds a socket (and may have done the key exchange) but has not named a user
    CONNECTED = 0
    #: it named a user and is authenticating (or sits at a password prompt)
    AUTHENTICATING = 1
    #: a password of it is being checked (or waits out its delay)
    CHECKING = 2


@dataclass
class _Place:
    """A connection's place at the login."""

    source: str
    opened: float
    stage: Stage = Stage.CONNECTED


@dataclass(frozen=True)
class Eviction(Generic[Key]):
    """A connection closed to make room for a new one: its place is free at once."""

    key: Key
    source: str
    #: seconds it held its place without logging in (charged to its source)
    held: float
    #: the charge started its source's penalty
    penalized: bool


@dataclass(frozen=True)
class Admission(Generic[Key]):
    """What the gate makes of a new connection: let in (perhaps in the place of an older one)
    or closed at once, and why."""

    refused: str | None = None
    evicted: Eviction[Key] | None = None


class ConnectionGate(Generic[Key]):
    """Caps on connections not logged in yet and on password attempts waiting out a delay.

    Connections are counted by source (:func:`.sources.source_of`) and known by a key the
    server chooses (its connection object); password attempts are counted by address.

    When a new connection would find the places full, or be dropped at random past the start,
    it takes the place of a connection that has held one for longer than
    ``unauthenticated_grace`` without logging in, if there is one: of those that have come the
    least far (see :class:`Stage`), one of the source holding the most places, the oldest of
    them. That connection is charged to its source as one that went without logging in. A
    student's client logs in well within the grace, so only connections that sit on their
    place make room, and the sources that keep making new ones are soon refused."""

    def __init__(self, policy: LoginPolicy, clock: Clock = time.monotonic) -> None:
        self.policy = policy
        self.unauthenticated: Counter[str] = Counter()
        self.waiting: Counter[str] = Counter()
        self.penalties = Penalties(policy.penalty_least, policy.penalty_longest, clock)
        self._clock = clock
        self._places: dict[Key, _Place] = {}
        self._random = random.Random(policy.seed)

    def admit(self, key: Key, address: str) -> Admission[Key]:
        """Let a new connection from ``address`` in, known as ``key`` from now on, or say why
        it is closed at once."""
        policy = self.policy
        source = source_of(address)
        penalty = self.penalties.refused_for(source)
        if penalty:
            return Admission(
                f"refused for another {penalty:.0f} s: connections from {source} held places "
                "at the login without logging in"
            )
        if self.unauthenticated[source] >= policy.max_unauthenticated_per_address:
            where = "this address" if source == address else source
            return Admission(
                f"{policy.max_unauthenticated_per_address} connections from {where} "
                "have not logged in yet"
            )
        crowded = self._crowded()
        evicted = None
        if crowded is not None:
            evicted = self._evict()
            if evicted is None:
                return Admission(crowded)
        self._places[key] = _Place(source, self._clock())
        self.unauthenticated[source] += 1
        return Admission(evicted=evicted)

    def _crowded(self) -> str | None:
        """Why a new connection finds no place: all taken, or dropped at random past the
        start (as OpenSSH's MaxStartups); None when it finds one."""
        policy = self.policy
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

    def _evict(self) -> Eviction[Key] | None:
        """Free the place of the connection that makes room (see the class), if one may."""
        now = self._clock()
        grace = self.policy.unauthenticated_grace
        oldest = next(iter(self._places.values()), None)  # kept in the order they came
        if oldest is None or now - oldest.opened <= grace:
            return None
        stale = [(k, p) for k, p in self._places.items() if now - p.opened > grace]
        key, place = min(
            stale, key=lambda kp: (kp[1].stage, -self.unauthenticated[kp[1].source], kp[1].opened)
        )
        held = now - place.opened
        self._release(key)
        penalized = self.penalties.charge(place.source, held)
        return Eviction(key, place.source, held, penalized)

    def progressed(self, key: Key, stage: Stage) -> None:
        """The connection ``key`` has come as far as ``stage`` (or gone back, after a password
        check)."""
        place = self._places.get(key)
        if place is not None:
            place.stage = stage

    def settled(self, key: Key, logged_in: bool = True) -> bool:
        """The connection ``key`` logged in or went away: it no longer holds a place; one that
        went without logging in is charged to its source for the time it held it. True when
        that starts the source's penalty. Nothing happens for a connection that holds no place
        (never let in, or closed to make room)."""
        place = self._release(key)
        if place is None or logged_in:
            return False
        return self.penalties.charge(place.source, self._clock() - place.opened)

    def _release(self, key: Key) -> _Place | None:
        place = self._places.pop(key, None)
        if place is not None:
            self.unauthenticated[place.source] -= 1
            if self.unauthenticated[place.source] <= 0:
                del self.unauthenticated[place.source]
        return place

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
