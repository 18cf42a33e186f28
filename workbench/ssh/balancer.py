"""The HAProxy configuration that puts several lab servers behind one address.

HAProxy passes each SSH connection through as TCP (it never sees keys or passwords), sends a
new connection to the server holding the fewest, starts each with a PROXY protocol header
naming the student's address (the servers run with ``--proxy-protocol``), and takes a server
that stops accepting connections out of the rotation by a TCP health check. docs/deploy.md
shows this text as the balancer test runs it; the test and the documentation both take it
from here.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

TEMPLATE = """\
global
    stats socket {stats} mode 600 level admin

defaults
    mode tcp
    timeout connect 5s
    # a quiet SSH session stays open: the lab server sends a keepalive every 30 s
    timeout client 10m
    timeout server 10m
    timeout check 3s
    # a connection a server refuses is tried again, on another server
    retries 3
    option redispatch

frontend lab
    bind {listen}
    default_backend lab_servers

backend lab_servers
    balance leastconn
    # a TCP connection every 2 s; 2 failures take a server out, 2 successes bring it back;
    # each connection starts with the student's address (serve-ssh --proxy-protocol)
    default-server check inter 2s fall 2 rise 2 send-proxy-v2
{servers}
"""


@dataclass(frozen=True)
class LabBackend:
    """One lab server as HAProxy names it, and the address of its ``serve-ssh`` port."""

    name: str
    address: str  # HOST:PORT


def haproxy_config(listen: str, servers: Sequence[LabBackend], stats: str) -> str:
    """HAProxy's configuration: students connect to ``listen`` (``[HOST]:PORT``) and are
    spread over ``servers``; ``stats`` is where its admin socket listens (a path, or
    ``ipv4@HOST:PORT``)."""
    if not servers:
        raise ValueError("a balancer needs at least one lab server")
    lines = "\n".join(f"    server {s.name} {s.address}" for s in servers)
    return TEMPLATE.format(listen=listen, servers=lines, stats=stats)


#: the example docs/deploy.md shows: two lab servers, students connecting to port 2222
EXAMPLE = haproxy_config(
    ":2222",
    [LabBackend("lab1", "10.0.0.11:2222"), LabBackend("lab2", "10.0.0.12:2222")],
    "/run/haproxy/admin.sock",
)
