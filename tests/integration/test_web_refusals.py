"""Bad input at the browser door, over real sockets on loopback: each refused, said in one log
line, and the student already at work goes on unaffected."""

from __future__ import annotations

import asyncio
import logging
import re
import socket

import aiohttp
import pytest

from tests.app.support import sync
from tests.waiting import until
from workbench.door.logins import LoginPolicy
from workbench.web.cookies import SESSION_COOKIE

from .ssh_support import Account, distance, moved
from .web_support import PASSWORD, WebHost, web_host

ACCOUNTS = [Account("ann", password=PASSWORD), Account("bob", password=PASSWORD)]


def lines(caplog, text: str) -> list[str]:
    return [r.getMessage() for r in caplog.records if text in r.getMessage()]


async def working(host: WebHost):
    """Bob logged in, at his workbench and driving: the session that must go on."""
    browser = host.browser()
    await browser.login("bob")
    page = await browser.page()
    await page.start_app()
    return browser, page


async def still_working(page) -> None:
    before = distance(page.text())
    page.send("s" if moved(page.text()) else "w")
    await page.wait_until(lambda t: distance(t) != before, "bob's robot answering a key")


async def refused_upgrade(browser, **options) -> int:
    with pytest.raises(aiohttp.WSServerHandshakeError) as refused:
        await browser.page(**options)
    return refused.value.status


@sync
async def test_websockets_without_a_login_with_a_forged_cookie_or_another_origin(tmp_path, caplog):
    caplog.set_level(logging.INFO, "workbench.web")
    async with web_host(tmp_path, ACCOUNTS) as host:
        bob, bobs_page = await working(host)
        stranger = host.browser()
        assert await refused_upgrade(stranger) == 403
        forged = host.browser()
        forged.session.cookie_jar.update_cookies({SESSION_COOKIE: "A" * 43})
        assert await refused_upgrade(forged) == 403
        assert len(lines(caplog, "WebSocket refused: from 127.0.0.1: not logged in")) == 1
        # a logged-in student's cookie, from another site's page (a cross-site hijack)
        ann = host.browser()
        await ann.login("ann")
        assert await refused_upgrade(ann, origin="https://evil.example") == 403
        assert len(lines(caplog, "Origin https://evil.example is not this server's")) == 1
        assert "ann" not in host.server.apps
        await still_working(bobs_page)
        for browser in (stranger, forged, ann, bob):
            await browser.close()


@sync
async def test_a_login_without_the_form_token_or_from_another_site_is_refused(tmp_path, caplog):
    caplog.set_level(logging.INFO, "workbench.web")
    async with web_host(tmp_path, ACCOUNTS) as host:
        bob, bobs_page = await working(host)
        browser = host.browser()
        form = {"user": "ann", "password": PASSWORD, "csrf": "forged"}
        async with browser.session.post(f"{host.url}/login", data=form) as answer:
            assert answer.status == 403 and SESSION_COOKIE not in answer.cookies
        assert len(lines(caplog, "the form's token or origin is not this server's")) == 1
        # the form's own token, posted by another site's page
        async with browser.session.get(f"{host.url}/login") as page:
            token = re.search(r'name="csrf" value="([^"]+)"', await page.text())
        assert token is not None
        form["csrf"] = token.group(1)
        async with browser.session.post(
            f"{host.url}/login", data=form, headers={"Origin": "https://evil.example"}
        ) as answer:
            assert answer.status == 403 and SESSION_COOKIE not in answer.cookies
        # said once: the same refusal from one address again within 10 s is held back
        assert len(lines(caplog, "the form's token or origin is not this server's")) == 1
        answer = await browser.login("ann")  # the form itself, with its token: let in
        assert answer.status == 200 and answer.url.path == "/"
        await still_working(bobs_page)
        await browser.close()
        await bob.close()


@sync
async def test_a_guessing_run_locks_the_account_and_the_right_password_waits(tmp_path, caplog):
    caplog.set_level(logging.INFO, "workbench.web")
    policy = LoginPolicy(first_delay=0.01, max_delay=0.02, lock_after=5, lock_for=600)
    async with web_host(tmp_path, ACCOUNTS, logins=policy) as host:
        bob, bobs_page = await working(host)
        guesser = host.browser()
        for guess in range(6):
            answer = await guesser.login("ann", f"guess-{guess}")
            assert answer.status == 403 and answer.url.path == "/login"
        assert len(lines(caplog, "passwords of ann locked for 10 min after 5 failures")) == 1
        assert len(lines(caplog, "login refused: ann from 127.0.0.1: wrong password")) == 5
        answer = await guesser.login("ann", PASSWORD)
        assert answer.status == 403 and "Too many tries" in await answer.text()
        await still_working(bobs_page)
        await guesser.close()
        await bob.close()


@sync
async def test_a_megabyte_frame_closes_that_page_only(tmp_path, caplog):
    caplog.set_level(logging.INFO, "workbench.web")
    async with web_host(tmp_path, ACCOUNTS) as host:
        bob, bobs_page = await working(host)
        ann = host.browser()
        await ann.login("ann")
        page = await ann.page()
        await page.start_app()
        await page.socket.send_bytes(b"w" * (1 << 20))
        await page.closed()
        assert page.socket.close_code == 1009  # message too big
        assert len(lines(caplog, "page of ann from 127.0.0.1 closed")) == 1
        await still_working(bobs_page)
        await ann.close()
        await bob.close()


@sync
async def test_a_huge_resize_is_clamped_and_a_flood_of_them_passes_on_few(tmp_path, caplog):
    caplog.set_level(logging.INFO, "workbench.web")
    async with web_host(tmp_path, ACCOUNTS) as host:
        bob, bobs_page = await working(host)
        ann = host.browser()
        await ann.login("ann")
        page = await ann.page()
        await page.start_app()
        student = host.server.apps["ann"]
        passed: list[tuple[int, int]] = []
        resize = student.app.resize
        student.app.resize = lambda w, h: (passed.append((w, h)), resize(w, h))[1]
        page.resize(65535, 65535)
        await until(lambda: student.size == (500, 200), "the app given the clamped size")
        assert len(lines(caplog, "terminal of ann is 65535x65535: the app is given 500x200")) == 1
        for step in range(500):
            page.resize(80 + step % 40, 24 + step % 10)
        page.resize(100, 30)
        page.screen.resize(30, 100)
        await until(lambda: student.size == (100, 30), "the last size passed on")
        # at most one size per resize_every (0.1 s) went to the app, not five hundred, and
        # the flood is said in one line
        assert len(passed) < 100
        assert len(lines(caplog, "resizes from a page of ann come faster than one per")) == 1
        page.send("w")
        await page.wait_until(moved, "ann's app still answering")
        await still_working(bobs_page)
        await ann.close()
        await bob.close()


@sync
async def test_many_idle_websockets_from_ten_addresses_hold_nothing(tmp_path, caplog):
    caplog.set_level(logging.INFO, "workbench.web")
    async with web_host(tmp_path, ACCOUNTS) as host:
        bob, bobs_page = await working(host)

        async def from_address(last: int) -> list[int]:
            connector = aiohttp.TCPConnector(local_addr=(f"127.0.0.{last}", 0))
            async with aiohttp.ClientSession(connector=connector) as session:
                statuses = []
                for _ in range(10):
                    try:
                        await session.ws_connect(f"{host.url}/ws", origin=host.url)
                        statuses.append(101)
                    except aiohttp.WSServerHandshakeError as exc:
                        statuses.append(exc.status)
                return statuses

        answers = await asyncio.gather(*(from_address(n) for n in range(2, 12)))
        assert all(status == 403 for statuses in answers for status in statuses)
        assert sorted(host.server.apps) == ["bob"] and sum(host.server.pages_open.values()) == 1
        # one line for each address, however many it sent
        assert len(lines(caplog, "WebSocket refused")) == 10
        await still_working(bobs_page)
        await bob.close()


@sync
async def test_sockets_that_never_send_a_request_are_capped_per_address(tmp_path, caplog):
    caplog.set_level(logging.INFO, "workbench.web")
    policy = LoginPolicy(max_unauthenticated_per_address=4, login_timeout=30, penalty_longest=0)
    async with web_host(tmp_path, ACCOUNTS, logins=policy) as host:
        bob, bobs_page = await working(host)
        loop = asyncio.get_running_loop()
        idle = []
        for _ in range(8):
            sock = socket.socket()
            sock.setblocking(False)
            await loop.sock_connect(sock, ("127.0.0.1", host.server.port))
            idle.append(sock)
        await until(lambda: host.server.gate.unauthenticated["127.0.0.1"] == 4, "four held")
        await until(lambda: lines(caplog, "connection refused: from 127.0.0.1"), "a refusal")
        # the ones past the cap were closed at once; bob, logged in, goes on
        closed = 0
        for sock in idle:
            try:
                if await asyncio.wait_for(loop.sock_recv(sock, 1), 0.2) == b"":
                    closed += 1
            except TimeoutError:
                pass
            finally:
                sock.close()
        assert closed == 4
        await still_working(bobs_page)
        await bob.close()
