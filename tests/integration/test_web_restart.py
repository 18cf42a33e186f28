"""A browser door restarted mid-lab: the students' logins are kept (in the data folder, as
digests of their ids), so their pages come back to a new workbench without a login; a forged
cookie and an expired login are refused, each in one log line."""

from __future__ import annotations

import json
import logging

import pytest

from tests.app.support import sync
from workbench.web.cookies import LOGINS_FOLDER, SESSION_COOKIE, digest

from .ssh_support import Account
from .web_support import PASSWORD, web_host


def cookie_of(browser) -> str:
    return next(c.value for c in browser.session.cookie_jar if c.key == SESSION_COOKIE)


@sync
async def test_a_restart_keeps_a_student_logged_in_and_refuses_forged_or_expired_cookies(
    tmp_path, caplog
):
    caplog.set_level(logging.INFO, "workbench.web")
    accounts = [Account("ann", password=PASSWORD), Account("bob", password=PASSWORD)]
    async with web_host(tmp_path, accounts) as host:
        ann, bob = host.browser(), host.browser()
        await ann.login("ann")
        await bob.login("bob")
        page = await ann.page()
        await page.start_app()
        await page.close()
        form_token = ann.csrf
        kept = host.data_dir / LOGINS_FOLDER
        assert cookie_of(ann) not in "".join(p.read_text() for p in kept.iterdir())
    async with web_host(tmp_path, accounts) as again:  # the same data folder, a new server
        for browser in (ann, bob):
            browser.host = again
        page = await ann.page()
        await page.wait_for("Who is at this robot?", timeout=90)  # a new workbench, no login
        status, listing = await ann.get("/files")
        assert status == 200 and b"entries" in listing
        # the page's form token still holds: an upload with it is taken
        assert (await ann.upload("kept.txt", b"x", csrf=form_token))[0] == 200
        # bob's login expired while the server was down: refused, and its file removed
        path = again.data_dir / LOGINS_FOLDER / digest(cookie_of(bob))
        said = json.loads(path.read_text())
        path.write_text(json.dumps(said | {"expires": 1.0}))
        with pytest.raises(Exception) as refused:
            await bob.page()
        assert getattr(refused.value, "status", None) == 403 and not path.exists()
        forged = again.browser()
        forged.session.cookie_jar.update_cookies({SESSION_COOKIE: "A" * 43})
        with pytest.raises(Exception) as refused:
            await forged.page()
        assert getattr(refused.value, "status", None) == 403
        assert len([r for r in caplog.records if "not logged in" in r.getMessage()]) == 1
        assert sorted(again.server.apps) == ["ann"]
        await page.close()
        for browser in (ann, bob, forged):
            await browser.close()
