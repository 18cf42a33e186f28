"""The browser door from a browser's side, over real sockets on loopback: a student logs in
with the course's account, passes the names dialog, drives, reloads the page and finds the
same workbench; a second tab takes it over; a page that does not come back ends its app; an
instructor gets the console."""

from __future__ import annotations

from tests.app.support import sync
from tests.waiting import until

from .ssh_support import Account, moved
from .web_support import PASSWORD, web_host


@sync
async def test_a_student_logs_in_drives_reloads_and_finds_the_same_workbench(tmp_path):
    async with web_host(tmp_path, [Account("ann", password=PASSWORD)]) as host:
        browser = host.browser()
        answer = await browser.login("ann")
        assert answer.status == 200 and answer.url.path == "/"
        page = await browser.page()
        await page.start_app()
        page.send("w")
        screen = await page.wait_until(moved, "the robot moving")
        pid = host.server.apps["ann"].app.pid
        await page.close()  # a reload: the page's socket goes, the page comes back
        again = await browser.page()
        # the same app, its screen drawn again whole: no names dialog, the distance driven
        redrawn = await again.wait_until(moved, "the screen redrawn")
        assert "Who is at this robot?" not in redrawn
        assert host.server.apps["ann"].app.pid == pid
        assert "ann (student)" in screen
        await again.close()
        await browser.close()


@sync
async def test_a_second_tab_takes_the_workbench_over_and_the_first_is_told(tmp_path):
    async with web_host(tmp_path, [Account("ann", password=PASSWORD)]) as host:
        browser = host.browser()
        await browser.login("ann")
        first = await browser.page()
        await first.start_app()
        second = await browser.page()
        await second.wait_for("distance 0.00 unit")
        await first.closed()
        assert first.notices[-1]["type"] == "taken"
        assert "another tab" in first.notices[-1]["message"]
        second.send("w")
        await second.wait_until(moved, "the second tab driving")
        assert len(host.server.apps) == 1
        await second.close()
        await browser.close()


@sync
async def test_a_page_that_does_not_come_back_ends_its_app_after_the_grace(tmp_path):
    async with web_host(tmp_path, [Account("ann", password=PASSWORD)], reattach_grace=0.5) as host:
        browser = host.browser()
        await browser.login("ann")
        page = await browser.page()
        await page.start_app()
        process = host.server.apps["ann"].app
        await page.close()
        await until(lambda: "ann" not in host.server.apps, "the app ended after the grace")
        assert process.returncode is not None
        fresh = await browser.page()
        await fresh.wait_for("Who is at this robot?", timeout=90)  # a new workbench
        await fresh.close()
        await browser.close()


@sync
async def test_an_instructor_gets_the_console(tmp_path):
    async with web_host(tmp_path, [Account("prof", "instructor", password=PASSWORD)]) as host:
        browser = host.browser()
        await browser.login("prof")
        page = await browser.page()
        screen = await page.wait_for("Sign-off queue", "console of prof", timeout=90)
        assert "Who is at this robot?" not in screen
        assert host.server.apps["prof"].app.returncode is None
        await page.close()
        await browser.close()
