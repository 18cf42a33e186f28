"""The browser door behind a sign-on proxy (the user named in a header, believed from the
proxy's addresses only) and over TLS (cookies marked Secure)."""

from __future__ import annotations

import datetime
import logging

from cryptography import x509
from cryptography.hazmat.primitives import hashes, serialization
from cryptography.hazmat.primitives.asymmetric import ec
from cryptography.x509.oid import NameOID

from tests.app.support import sync
from workbench.door.networks import parse_networks
from workbench.web.cookies import SESSION_COOKIE

from .ssh_support import Account
from .web_support import PASSWORD, web_host

HEADER = "X-Forwarded-User"
ACCOUNTS = [Account("ann", password=PASSWORD)]


def lines(caplog, text: str) -> list[str]:
    return [r.getMessage() for r in caplog.records if text in r.getMessage()]


@sync
async def test_the_proxy_names_the_user_and_its_page_gets_the_workbench(tmp_path, caplog):
    caplog.set_level(logging.INFO, "workbench.web")
    proxy = parse_networks("127.0.0.1")
    async with web_host(tmp_path, ACCOUNTS, user_header=HEADER, trusted_proxies=proxy) as host:
        browser = host.browser(headers={HEADER: "ann"})
        async with browser.session.get(f"{host.url}/") as answer:
            assert answer.status == 200 and 'data-user="ann"' in await answer.text()
        assert lines(caplog, "login: ann (student) from 127.0.0.1 by the X-Forwarded-User header")
        page = await browser.page()
        await page.wait_for("Who is at this robot?", timeout=90)
        await page.close()
        # a name the users file does not hold, and a password, are refused
        other = host.browser(headers={HEADER: "mallory"})
        async with other.session.get(f"{host.url}/") as answer:
            assert answer.status == 403
        assert lines(caplog, "names mallory, who is not in the users file")
        plain = host.browser()
        form = {"user": "ann", "password": PASSWORD}
        async with plain.session.post(f"{host.url}/login", data=form) as answer:
            assert answer.status == 403 and "sign-on" in await answer.text()
        for each in (browser, other, plain):
            await each.close()


@sync
async def test_the_header_from_an_address_that_is_not_the_proxy_is_refused(tmp_path, caplog):
    caplog.set_level(logging.INFO, "workbench.web")
    proxy = parse_networks("10.9.9.9")
    async with web_host(tmp_path, ACCOUNTS, user_header=HEADER, trusted_proxies=proxy) as host:
        browser = host.browser(headers={HEADER: "ann"})
        async with browser.session.get(f"{host.url}/") as answer:
            assert answer.status == 403 and SESSION_COOKIE not in answer.cookies
        said = lines(caplog, "X-Forwarded-User sent from 127.0.0.1, which is not a trusted proxy")
        assert len(said) == 1 and "ann" not in host.server.apps
        await browser.close()


def self_signed(folder) -> tuple:
    key = ec.generate_private_key(ec.SECP256R1())
    name = x509.Name([x509.NameAttribute(NameOID.COMMON_NAME, "127.0.0.1")])
    now = datetime.datetime.now(datetime.UTC)
    cert = (
        x509.CertificateBuilder()
        .subject_name(name)
        .issuer_name(name)
        .public_key(key.public_key())
        .serial_number(x509.random_serial_number())
        .not_valid_before(now - datetime.timedelta(days=1))
        .not_valid_after(now + datetime.timedelta(days=1))
        .sign(key, hashes.SHA256())
    )
    cert_path, key_path = folder / "cert.pem", folder / "key.pem"
    cert_path.write_bytes(cert.public_bytes(serialization.Encoding.PEM))
    key_path.write_bytes(
        key.private_bytes(
            serialization.Encoding.PEM,
            serialization.PrivateFormat.PKCS8,
            serialization.NoEncryption(),
        )
    )
    return cert_path, key_path


@sync
async def test_over_tls_the_login_cookie_is_secure_httponly_strict_and_expires(tmp_path):
    cert, key = self_signed(tmp_path)
    async with web_host(tmp_path, ACCOUNTS, tls_cert=cert, tls_key=key) as host:
        assert host.url.startswith("https://")
        browser = host.browser()
        answer = await browser.login("ann")
        assert answer.status == 200 and answer.url.path == "/"
        cookie = next(r for r in answer.history if SESSION_COOKIE in r.cookies).cookies[
            SESSION_COOKIE
        ]
        assert cookie["secure"] and cookie["httponly"] and cookie["samesite"] == "Strict"
        assert int(cookie["max-age"]) == 12 * 3600
        await browser.close()
