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
from .test_spare_apps import children
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


@pytest.mark.parametrize("spares", [0, 1], ids=["forked", "spare app"])
@sync
async def test_a_student_drives_in_chromium_and_a_reload_finds_the_same_workbench(tmp_path, spares):
    async with (
        web_host(tmp_path, [Account("ann", password=PASSWORD)], spare_apps=spares) as host,
        playwright.async_playwright() as driver,
    ):
        waiting: set[int] = set()
        if spares:  # the app started ahead is the one ann gets
            forkserver = host.server.forkserver
            assert forkserver is not None
            await until(lambda: len(children(forkserver.pid)) == 1, "a spare app waiting", 60)
            waiting = children(forkserver.pid)
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
            assert (pid in waiting) == bool(spares)
            await page.reload()
            again = await wait_for_screen(page, moved, "the same workbench after a reload")
            assert "Who is at this robot?" not in again
            assert host.server.apps["ann"].app.pid == pid
            await until(lambda: host.server.pages_open.get("ann") == 1, "one page open")
            assert problems == []
        finally:
            await browser.close()


#: what a test's key string is as Playwright's key names (the rest is typed as it is)
KEY_NAMES = {"\r": "Enter", "\t": "Tab", " ": "Space", "\x13": "Control+s", "\x1b[B": "ArrowDown"}


class ChromiumTerminal:
    """A Chromium page's terminal with the waits and keys of ``ssh_support.Terminal``, so
    the lab helpers drive it: keys go through Playwright's keyboard one after another, in the
    order sent; the screen is read from xterm.js's buffer."""

    def __init__(self, page) -> None:
        self.page = page
        self._keys: asyncio.Task[None] | None = None
        self._last = ""

    def send(self, keys: str) -> None:
        before = self._keys

        async def press() -> None:
            if before is not None:
                await before
            name = KEY_NAMES.get(keys)
            if name is not None:
                await self.page.keyboard.press(name)
            else:
                await self.page.keyboard.type(keys)

        self._keys = asyncio.get_running_loop().create_task(press())

    def text(self) -> str:
        return self._last

    async def wait_until(self, check, what: str, timeout: float = 20.0) -> str:
        if self._keys is not None:
            await self._keys
        loop = asyncio.get_running_loop()
        end = loop.time() + timeout
        while not check(text := await screen_text(self.page)):
            if loop.time() > end:
                raise AssertionError(f"{what}: not on the page after {timeout:g} s:\n{text}")
            await asyncio.sleep(0.1)
        self._last = text
        return text

    async def wait_for(self, *needles: str, timeout: float = 20.0) -> str:
        return await self.wait_until(
            lambda text: all(n in text for n in needles), f"{list(needles)}", timeout
        )


async def log_in(page, url: str, name: str) -> None:
    await page.goto(f"{url}/")
    await page.fill("input[name=user]", name)
    await page.fill("input[name=password]", PASSWORD)
    await page.click("button[type=submit]")
    await page.wait_for_url(f"{url}/")


@sync
async def test_an_instructor_signs_in_their_own_chromium_and_the_students_page_shows_it(tmp_path):
    """Two browsers (contexts: cookies of their own): the student asks for sign-off on
    theirs; the instructor logs in on the other, types the passphrase there and signs; the
    student's page shows the sign-off."""
    from workbench.labs.signoff.instructors import KdfParams, create_instructor
    from workbench.labs.store.store import Store

    from .ssh_support import open_exercise

    passphrase = "correct horse battery"
    accounts = [Account("ann", password=PASSWORD), Account("ito", "instructor", password=PASSWORD)]
    async with (
        web_host(tmp_path, accounts) as host,
        playwright.async_playwright() as driver,
    ):
        create_instructor(host.data_dir, "ito", passphrase, kdf=KdfParams(n=2**10, r=8, p=1))
        browser = await driver.chromium.launch(
            executable_path=CHROMIUM, args=["--no-sandbox", "--disable-gpu"]
        )
        try:
            viewport = {"width": 1000, "height": 640}
            anns, itos = [await browser.new_context(viewport=viewport) for _ in range(2)]
            problems: list[str] = []
            pages = [await anns.new_page(), await itos.new_page()]
            for page in pages:
                page.on("pageerror", lambda error: problems.append(str(error)))
            student_page, instructor_page = pages
            await log_in(student_page, host.url, "ann")
            student = ChromiumTerminal(student_page)
            await student.wait_for("Who is at this robot?", timeout=90)
            student.send("\r")
            await student.wait_for("distance 0.00 unit")
            await open_exercise(student, "Unity simulator: Drive by wire")
            student.send("i")
            student.send("r")
            await student.wait_for("1st in the queue")

            await log_in(instructor_page, host.url, "ito")
            instructor = ChromiumTerminal(instructor_page)
            await instructor.wait_for("Sign-off queue: 1 waiting", "1. ann", timeout=90)
            instructor.send("\r")
            await instructor.wait_for("ann ask for sign-off", "objectives pass")
            instructor.send(passphrase)  # typed on the instructor's own page
            await instructor.wait_for("•" * len(passphrase))
            instructor.send("\t")
            instructor.send("checked at the console")
            await instructor.wait_for("at the console")
            instructor.send("\t")
            instructor.send(" ")
            await instructor.wait_for("[X] Override")
            instructor.send("\x13")  # ctrl+s signs
            await instructor.wait_for("signed off ann unity-simulator/drive-by-wire as ito")
            await student.wait_for("[*] Drive by wire", "signed off by ito on")
            assert sorted(host.server.apps) == ["ann", "ito"]
            assert problems == []
        finally:
            await browser.close()

    with Store.open(host.data_dir, create=False) as store:
        (record,) = store.signoffs.of()
    assert (record.instructor, record.student, record.override) == ("ito", "ann", True)
