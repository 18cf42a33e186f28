"""The PROXY protocol header a load balancer sends before the SSH banner: the client's address
is read from well-formed headers, anything else is refused with the parser's own error, and the
reader never asks for a byte past the header."""

from __future__ import annotations

import ipaddress
import struct

import pytest
from hypothesis import given
from hypothesis import strategies as st

from workbench.door.networks import parse_networks, trusted
from workbench.ssh.proxy_protocol import (
    V2_MAX_BODY,
    V2_SIGNATURE,
    ProxyHeader,
    ProxyHeaderError,
    bytes_wanted,
    parse_header,
)


def v2(source: str, command: int = 1, extra: bytes = b"") -> bytes:
    """A version 2 header as HAProxy's send-proxy-v2 writes it (TLVs as ``extra``)."""
    ip = ipaddress.ip_address(source)
    family = 0x11 if ip.version == 4 else 0x21
    dest = ipaddress.ip_address("10.0.0.11" if ip.version == 4 else "fd00::11")
    body = ip.packed + dest.packed + struct.pack("!HH", 50123, 2222) + extra
    return V2_SIGNATURE + bytes([0x20 | command, family]) + struct.pack("!H", len(body)) + body


def read_like_the_server(stream: bytes) -> tuple[ProxyHeader, bytes]:
    """Take the header off ``stream`` as the server does, asking only for the bytes wanted;
    the header and what is left for SSH."""
    data = b""
    while wanted := bytes_wanted(data):
        chunk = stream[len(data) : len(data) + wanted]
        if not chunk:
            raise ProxyHeaderError("cut short")
        data += chunk
    return parse_header(data), stream[len(data) :]


BANNER = b"SSH-2.0-OpenSSH_9.6\r\n"


def test_a_v2_header_names_the_ipv4_client_and_leaves_the_ssh_banner_unread():
    header, rest = read_like_the_server(v2("192.0.2.7") + BANNER)
    assert header.client == "192.0.2.7"
    assert rest == BANNER


def test_a_v2_header_names_an_ipv6_client_even_with_tlvs_after_the_addresses():
    tlv = b"\x04" + struct.pack("!H", 3) + b"abc"  # a NOOP TLV
    header, rest = read_like_the_server(v2("2001:db8::7", extra=tlv) + BANNER)
    assert header.client == "2001:db8::7"
    assert rest == BANNER


def test_a_local_header_from_a_health_check_names_no_client():
    header, rest = read_like_the_server(v2("192.0.2.7", command=0) + BANNER)
    assert (header.client, header.local) == (None, True)
    assert rest == BANNER


def test_a_v1_text_header_names_the_client():
    header, rest = read_like_the_server(b"PROXY TCP4 192.0.2.9 10.0.0.11 5555 2222\r\n" + BANNER)
    assert header.client == "192.0.2.9"
    assert rest == BANNER
    header, _ = read_like_the_server(b"PROXY UNKNOWN\r\n" + BANNER)
    assert (header.client, header.local) == (None, False)


@pytest.mark.parametrize(
    ("stream", "says"),
    [
        (BANNER, "did not start with a PROXY protocol header"),
        (b"GET / HTTP/1.1\r\n", "did not start with a PROXY protocol header"),
        (v2("192.0.2.7")[:20], "cut short"),
        (V2_SIGNATURE + b"\x21\x11" + struct.pack("!H", 4) + b"\x01\x02\x03\x04", "too short"),
        (V2_SIGNATURE + b"\x21\x11" + struct.pack("!H", V2_MAX_BODY + 1), "claims 513 bytes"),
        (V2_SIGNATURE + b"\x31\x11" + struct.pack("!H", 0), "version 3"),
        (V2_SIGNATURE + b"\x25\x11" + struct.pack("!H", 0), "command 5"),
        (V2_SIGNATURE + b"\x21\x12" + struct.pack("!H", 12) + bytes(12), "UDP"),
        (V2_SIGNATURE + b"\x21\x51" + struct.pack("!H", 0), "unknown address family"),
        (b"PROXY TCP4 " + b"1" * 120, "no end within 107 bytes"),
        (b"PROXY TCP4 192.0.2.300 10.0.0.11 1 2\r\n", "not one"),
        (b"PROXY TCP6 192.0.2.3 10.0.0.11 1 2\r\n", "do not fit"),
        (b"PROXY TCP4 192.0.2.3 10.0.0.11 1\r\n", "is not 'PROXY TCP4"),
        (b"PROXY TCP4 192.0.2.3 10.0.0.11 1 99999\r\n", "port out of range"),
    ],
)
def test_a_malformed_header_is_refused_with_what_is_wrong(stream, says):
    with pytest.raises(ProxyHeaderError, match=says):
        read_like_the_server(stream)


@given(st.binary(max_size=700))
def test_any_bytes_give_a_header_or_the_parser_s_own_error_never_reading_past_it(stream):
    try:
        header, rest = read_like_the_server(stream)
    except ProxyHeaderError:
        return
    assert header.length <= 16 + V2_MAX_BODY
    assert stream == stream[: header.length] + rest


@given(st.binary(max_size=40))
def test_any_bytes_after_a_valid_header_are_left_alone(after):
    header, rest = read_like_the_server(v2("198.51.100.4") + after)
    assert (header.client, rest) == ("198.51.100.4", after)


def test_only_the_balancer_s_addresses_are_trusted():
    networks = parse_networks("127.0.0.1, 10.0.0.0/24,fd00::/8")
    assert trusted("127.0.0.1", networks)
    assert trusted("10.0.0.200", networks)
    assert trusted("::ffff:10.0.0.3", networks)
    assert trusted("fd00::11", networks)
    assert not trusted("127.0.0.2", networks)
    assert not trusted("10.0.1.1", networks)
    assert not trusted("not an address", networks)


@pytest.mark.parametrize("text", ["", "10.0.0.1,", "lab-balancer", "10.0.0.0/33"])
def test_a_balancer_list_that_is_not_addresses_is_refused(text):
    with pytest.raises(ValueError, match="address"):
        parse_networks(text)
