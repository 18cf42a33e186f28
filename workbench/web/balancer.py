"""The HAProxy configuration that puts several browser doors behind one address.

HAProxy speaks HTTP to the browsers (ending TLS in the deployment), sends a new student to the
server holding the fewest connections and keeps sending them there by a cookie of its own (their
app runs on that server), passes the student's address on (``X-Forwarded-For``, believed from
``serve-web --trusted-proxy``) and takes a server that stops answering out by a health check;
a student whose server is gone is sent to another. docs/deploy.md shows this text as the
balancer test runs it; both take it from here.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

TEMPLATE = """\
global
    stats socket {stats} mode 600 level admin

defaults
    mode http
    timeout connect 5s
    # a page's WebSocket stays open while the student works
    timeout client 1h
    timeout server 1h
    timeout tunnel 1h
    timeout check 3s
    # a request a dead server cannot take goes to another
    retries 3
    option redispatch

frontend web
    bind {listen}
    default_backend web_servers

backend web_servers
    balance leastconn
    option forwardfor
    http-request set-header X-Forwarded-Proto {proto}
    # sticky: a student's pages and reloads go to the server running their app
    cookie workbench_server insert indirect nocache httponly{secure}
    # the login page every 2 s; 2 failures take a server out, 2 successes bring it back
    option httpchk GET /login
    default-server check inter 2s fall 2 rise 2
{servers}
"""


@dataclass(frozen=True)
class WebBackend:
    """One browser door as HAProxy names it, and the address of its ``serve-web`` port."""

    name: str
    address: str  # HOST:PORT


def haproxy_config(
    listen: str, servers: Sequence[WebBackend], stats: str, *, tls: bool = True
) -> str:
    """HAProxy's configuration: browsers reach ``listen`` (its ``bind`` line: an address, and
    ``ssl crt FILE`` with ``tls``) and are spread over ``servers``; ``stats`` is where its admin
    socket listens."""
    if not servers:
        raise ValueError("a balancer needs at least one browser door")
    lines = "\n".join(f"    server {s.name} {s.address} cookie {s.name}" for s in servers)
    return TEMPLATE.format(
        listen=listen,
        servers=lines,
        stats=stats,
        proto="https" if tls else "http",
        secure=" secure" if tls else "",
    )


#: the example docs/deploy.md shows: two servers, browsers reaching port 443 with TLS
EXAMPLE = haproxy_config(
    ":443 ssl crt /etc/haproxy/lab.example.edu.pem",
    [WebBackend("web1", "10.0.0.11:8080"), WebBackend("web2", "10.0.0.12:8080")],
    "/run/haproxy/admin-web.sock",
)
