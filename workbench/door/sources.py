"""Where connections come from, as the lab server counts them: a source is an IPv4 address,
or an IPv6 address's /64 (one site's whole network: anyone with one holds any number of
addresses in it), and a source whose connections keep places at the login without logging in
is refused for a while (its penalty).

Plain bookkeeping with an injectable clock, like :mod:`.logins`.
"""

from __future__ import annotations

import ipaddress
import time
from collections.abc import Callable
from dataclasses import dataclass

Clock = Callable[[], float]

#: sources with a penalty kept at most; past it the expired ones are swept out, then the
#: nearest to their end down to three quarters of it (an attacker with many addresses cannot
#: grow the table without end)
MAX_PENALIZED = 65_536


def source_of(address: str) -> str:
    """The source ``address`` counts as: an IPv4 address itself (also written as IPv6,
    ``::ffff:10.0.0.7``), an IPv6 address's /64 network; anything else as it is."""
    try:
        ip = ipaddress.ip_address(address.partition("%")[0])
    except ValueError:
        return address
    if isinstance(ip, ipaddress.IPv6Address):
        if ip.ipv4_mapped is not None:
            return str(ip.ipv4_mapped)
        return str(ipaddress.IPv6Network((ip, 64), strict=False))
    return str(ip)


@dataclass
class _Penalty:
    until: float
    #: refused until ``until``: the debt reached the policy's minimum once
    active: bool = False


class Penalties:
    """Seconds charged to each source for the time its connections held a place at the login
    and then went without logging in.

    A charge moves the source's penalty that much further into the future (from now, or from
    where it already ends), up to ``longest`` seconds ahead; once the penalty reaches
    ``least`` seconds the source is refused until it ends. Time pays the debt back, so a
    source holds on average less than one place at the login before it is refused: a lab
    behind one address, whose students log in within seconds, is never refused.
    """

    def __init__(self, least: float, longest: float, clock: Clock = time.monotonic) -> None:
        self.least = least
        self.longest = longest
        self._clock = clock
        self._penalties: dict[str, _Penalty] = {}

    @property
    def enabled(self) -> bool:
        return self.longest > 0

    def charge(self, source: str, seconds: float) -> bool:
        """Charge ``source``; True when this charge starts its refusal."""
        if not self.enabled or seconds <= 0:
            return False
        now = self._clock()
        penalty = self._penalties.get(source)
        if penalty is None or penalty.until <= now:
            penalty = self._penalties[source] = _Penalty(now)
        penalty.until = min(penalty.until + seconds, now + self.longest)
        starts = not penalty.active and penalty.until - now >= self.least
        penalty.active = penalty.active or starts
        if len(self._penalties) > MAX_PENALIZED:
            self._sweep(now)
        return starts

    def refused_for(self, source: str) -> float:
        """Seconds ``source`` is still refused for (0: it is let in)."""
        penalty = self._penalties.get(source)
        if penalty is None:
            return 0.0
        left = penalty.until - self._clock()
        if left <= 0:
            del self._penalties[source]
            return 0.0
        return left if penalty.active else 0.0

    def _sweep(self, now: float) -> None:
        kept = {s: p for s, p in self._penalties.items() if p.until > now}
        if len(kept) > MAX_PENALIZED:
            keep = MAX_PENALIZED * 3 // 4
            latest = sorted(kept.items(), key=lambda item: item[1].until)[-keep:]
            kept = dict(latest)
        self._penalties = kept
