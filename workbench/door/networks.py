"""Addresses a door believes more of: the load balancers and proxies in front of it, given
as addresses or networks (``--proxy-protocol`` of ``serve-ssh``, ``--trusted-proxy`` of
``serve-web``)."""

from __future__ import annotations

import ipaddress
from collections.abc import Sequence

Network = ipaddress.IPv4Network | ipaddress.IPv6Network


def parse_networks(text: str) -> tuple[Network, ...]:
    """``"127.0.0.1,10.0.0.0/24"`` as networks; ValueError naming the bad part."""
    parts = [part.strip() for part in text.split(",")]
    if not text.strip() or not all(parts):
        raise ValueError(f"{text!r}: give the balancer's addresses, comma-separated")
    networks = []
    for part in parts:
        try:
            networks.append(ipaddress.ip_network(part, strict=False))
        except ValueError:
            raise ValueError(
                f"{part!r} is not an address or network (such as 10.0.0.5 or 10.0.0.0/24)"
            ) from None
    return tuple(networks)


def trusted(address: str, networks: Sequence[Network]) -> bool:
    """Whether the connection from ``address`` comes from a balancer."""
    try:
        ip = ipaddress.ip_address(address)
    except ValueError:
        return False
    if isinstance(ip, ipaddress.IPv6Address) and ip.ipv4_mapped is not None:
        ip = ip.ipv4_mapped
    return any(ip.version == net.version and ip in net for net in networks)
