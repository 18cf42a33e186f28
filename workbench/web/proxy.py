"""Who a request comes from when a proxy stands in front of the browser door.

A proxy in :attr:`WebConfig.trusted_proxies` (a load balancer, or an authenticating proxy
such as oauth2-proxy) is believed on two things: the client's address in the last entry of
``X-Forwarded-For`` (so the login limits count the student's address, not the proxy's), and,
in the trusted-header mode, the user it names in :attr:`WebConfig.user_header` once it has
signed them on. The same headers from any other address are never believed: a request that
names a user from elsewhere is refused and logged.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass

from workbench.door.networks import Network, trusted

FORWARDED_FOR = "X-Forwarded-For"
FORWARDED_PROTO = "X-Forwarded-Proto"


@dataclass(frozen=True)
class Origin:
    """Where a request came from, as the door believes it."""

    #: the client's address (behind a trusted proxy, the one it names)
    address: str
    #: the request came through a trusted proxy
    proxied: bool
    #: the page is https for the browser (TLS here, or a trusted proxy that says so)
    secure: bool


def origin_of(
    peer: str, headers: Mapping[str, str], proxies: Sequence[Network], tls: bool
) -> Origin:
    """Where a request from ``peer`` with ``headers`` came from."""
    if not proxies or not trusted(peer, proxies):
        return Origin(peer, False, tls)
    named = headers.get(FORWARDED_FOR, "").split(",")[-1].strip()
    proto = headers.get(FORWARDED_PROTO, "").strip().lower()
    return Origin(named or peer, True, tls or proto == "https")


@dataclass(frozen=True)
class HeaderLogin:
    """What the trusted header of one request says: nobody, a user, or a refusal."""

    user: str = ""
    refused: str = ""


def header_login(
    header: str, peer: str, headers: Mapping[str, str], proxies: Sequence[Network]
) -> HeaderLogin:
    """The user the trusted proxy names in ``header``; a refusal when a request names one
    without coming from a trusted proxy."""
    if not header:
        return HeaderLogin()
    named = headers.get(header, "").strip()
    if not named:
        return HeaderLogin()
    if not trusted(peer, proxies):
        return HeaderLogin(refused=f"{header} sent from {peer}, which is not a trusted proxy")
    return HeaderLogin(user=named)
