"""The browser door in a real browser: Debian's Chromium, headless, driven by Playwright.

A student logs in through the form, passes the names dialog, drives with ``w`` and sees the
robot move on the page's terminal (read from xterm.js's own buffer), reloads the page and finds
the same workbench. Skipped, with the reason, where Playwright or Chromium is missing (``make
test`` installs Chromium with apt-get when it runs as root)."""

from __future__ import annotations

import asyncio
import os
import shutil

import pytest

from tests.app.support import sync
from tests.waiting import until

from .ssh_support import Account, moved
from .web_support import PASSWORD, web_host

CHROMIUM = os.environ.get("WORKBENCH_CHROMIUM") or shutil.which("chromium") or "/usr/bin/chromium"
playwright = pytest.importorskip(
    "playwright.async_api", reason="Playwright's Python package is not installed (.[test])"
)
pytestmark = pytest.mark.skipif(
    not os.path.exists(CHROMIUM),
    reason=f"no Chromium at {CHROMIUM}: install Debian's chromium package (make test does, "
    "as root)",
)

#: the terminal's lines as xterm.js holds them
READ_SCREEN = """() => {
  const buffer = window.workbenchTerminal.buffer.active;
  const lines = [];
  for (let i = 0; i < buffer.length; i++) lines.push(buffer.getLine(i).translateToString(true));
  return lines.join("\\n");
}"""


async def screen_text(page) -> str:
    ready = await page.evaluate("() => Boolean(window.workbenchTerminal)")
    return await page.evaluate(READ_SCREEN) if ready else ""


async def wait_for_screen(page, check, what: str, timeout: float = 90.0) -> str:
    """Read the page's terminal until ``check`` holds; its text."""
    loop = asyncio.get_running_loop()
    end = loop.time() + timeout
    while not check(text := await screen_text(page)):
        if loop.time() > end:
            raise AssertionError(f"{what}: not on the page after {timeout:g} s:\n{text}")
        await asyncio.sleep(0.1)
    return text


@sync
async def test_a_student_drives_in_chromium_and_a_reload_finds_the_same_workbench(tmp_path):
    async with (
        web_host(tmp_path, [Account("ann", password=PASSWORD)]) as host,
        playwright.async_playwright() as driver,
    ):
        browser = await driver.chromium.launch(
            executable_path=CHROMIUM, args=["--no-sandbox", "--disable-gpu"]
        )
        try:
            page = await browser.new_page(viewport={"width": 1000, "height": 640})
            problems: list[str] = []
            page.on("pageerror", lambda error: problems.append(str(error)))
            page.on("console", lambda m: problems.append(m.text) if m.type == "error" else None)
            await page.goto(f"{host.url}/")
            assert page.url == f"{host.url}/login"
            await page.fill("input[name=user]", "ann")
            await page.fill("input[name=password]", PASSWORD)
            await page.click("button[type=submit]")
            await page.wait_for_url(f"{host.url}/")
            await wait_for_screen(page, lambda t: "Who is at this robot?" in t, "the names")
            await page.keyboard.press("Enter")
            await wait_for_screen(page, lambda t: "distance 0.00 unit" in t, "the main screen")
            await page.keyboard.press("w")
            await wait_for_screen(page, moved, "the robot moving")
            pid = host.server.apps["ann"].app.pid
            await page.reload()
            again = await wait_for_screen(page, moved, "the same workbench after a reload")
            assert "Who is at this robot?" not in again
            assert host.server.apps["ann"].app.pid == pid
            await until(lambda: host.server.pages_open.get("ann") == 1, "one page open")
            assert problems == []
        finally:
            await browser.close()
