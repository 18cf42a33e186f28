"""The per-user cap over both doors: an SSH server and a browser door serving one data folder
count a student's sessions together (each session's lease in the data folder), so a student
cannot open the cap's number by SSH and as many again in a browser."""

from __future__ import annotations

import logging

from tests.app.support import sync
from tests.waiting import until
from workbench.door.limits import SessionLimits

from .ssh_support import Account, lab_host
from .web_support import PASSWORD, web_host

REFUSED = "You already have 1 workbench session open, the most one user may have"


@sync
async def test_a_session_by_ssh_and_one_in_a_browser_count_against_one_cap(tmp_path, caplog):
    caplog.set_level(logging.INFO)
    limits = SessionLimits(per_user=1)
    accounts = [Account("ann", password=PASSWORD), Account("bob", password=PASSWORD)]
    async with (
        lab_host(tmp_path, accounts, limits) as ssh,
        web_host(tmp_path, accounts, limits) as web,
    ):
        assert ssh.data_dir == web.data_dir
        # ann at work over SSH: her browser gets no second workbench
        term = await ssh.terminal("ann", password=PASSWORD)
        await term.start_app()
        browser = web.browser()
        await browser.login("ann")
        page = await browser.page()
        await page.closed()
        assert page.notices[-1]["type"] == "ended" and REFUSED in page.notices[-1]["message"]
        assert "ann" not in web.server.apps
        # bob, another student, is not held by ann's count
        bobs = web.browser()
        await bobs.login("bob")
        bobs_page = await bobs.page()
        await bobs_page.start_app()
        # ann's SSH session ends: the browser may open hers, and then SSH may not
        await term.close()
        await until(lambda: web.server.leases.count("ann") == 0, "ann's SSH lease let go")
        page = await browser.page()
        await page.start_app()
        again = await ssh.terminal("ann", password=PASSWORD)
        await again.wait_for(REFUSED)
        assert [r for r in caplog.records if "session refused: ann" in r.getMessage()]
        for closing in (again, page, bobs_page, browser, bobs):
            await closing.close()
