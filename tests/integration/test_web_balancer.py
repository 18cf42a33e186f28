"""Two ``workbench serve-web`` behind a real HAProxy in HTTP mode, sharing one users file and
one PostgreSQL store, as docs/deploy.md sets them up: the student's pages stick to the server
running their app, and when that server is killed they log in again on the other and find
their file there."""

from __future__ import annotations

import asyncio
import os
import re
import signal
import subprocess
import sys
from dataclasses import dataclass
from pathlib import Path

import aiohttp
import pytest

from tests.app.support import sync
from tests.sessions import free_port
from tests.waiting import until
from workbench.door.users import users_path
from workbench.files.workspace import workspace_folder
from workbench.web.balancer import EXAMPLE, WebBackend, haproxy_config

from .ssh_support import Account, make_accounts, port_range
from .test_ssh_balancer import HAPROXY, end_left_over, needs_haproxy, stop
from .web_support import PASSWORD, Browser

ROOT = Path(__file__).resolve().parents[2]
PROGRAM = b"ann's program\n"


def test_the_deployment_guide_shows_the_configuration_the_web_balancer_test_runs():
    guide = (ROOT / "docs" / "deploy.md").read_text()
    assert f"```\n{EXAMPLE}```" in guide


@dataclass
class WebProcess:
    name: str
    data_dir: Path
    process: subprocess.Popen
    port: int = 0

    def log(self) -> str:
        path = self.data_dir / "web.log"
        return path.read_text(errors="replace") if path.exists() else ""

    def helpers(self) -> list[int]:
        """The fork server's and the apps' process ids, as the log gives them."""
        return [int(pid) for pid in re.findall(r"(?:fork server \(pid|, pid) (\d+)", self.log())]


def start_web(name: str, tmp_path: Path, shared: Path, db: str) -> WebProcess:
    low, high = port_range()
    with (tmp_path / f"{name}.out").open("wb") as out:
        process = subprocess.Popen(
            [
                sys.executable, "-m", "workbench", "serve-web", "--bind", "127.0.0.1",
                "--port", "0", "--data-dir", str(tmp_path / name),
                "--users", str(users_path(shared)), "--port-range", f"{low}-{high}",
                "--trusted-proxy", "127.0.0.1",
            ],
            stdout=out, stderr=subprocess.STDOUT, env=os.environ | {"WORKBENCH_DB": db},
        )  # fmt: skip
    return WebProcess(name, tmp_path / name, process)


async def serving(web: WebProcess) -> None:
    def port() -> int:
        assert web.process.poll() is None, (web.data_dir.parent / f"{web.name}.out").read_text()
        found = re.search(r"serving the browser door on 127\.0\.0\.1 port (\d+)", web.log())
        return int(found.group(1)) if found else 0

    web.port = await until(port, f"browser door {web.name} listening", timeout=120, every=0.1)


async def eventually(check, what: str, timeout: float = 60.0) -> None:
    """Ask ``check()`` (a coroutine function) until it says yes."""
    loop = asyncio.get_running_loop()
    deadline = loop.time() + timeout
    while not await check():
        assert loop.time() < deadline, f"{what}: not so after {timeout:g} s"
        await asyncio.sleep(0.1)


class Front:
    """What a Browser needs of a host: the balancer's address."""

    def __init__(self, port: int) -> None:
        self.url = f"http://127.0.0.1:{port}"


@needs_haproxy
@pytest.mark.long
@sync
async def test_a_student_sticks_to_one_server_and_outlives_its_loss(tmp_path, pg_url):
    shared = tmp_path / "shared"
    make_accounts(shared, [Account("ann", password=PASSWORD)])
    webs = [start_web(name, tmp_path, shared, pg_url) for name in ("web1", "web2")]
    haproxy = None
    try:
        for web in webs:
            await serving(web)
        port, stats = free_port(), free_port()
        config = tmp_path / "haproxy.cfg"
        config.write_text(
            haproxy_config(
                f"127.0.0.1:{port}",
                [WebBackend(w.name, f"127.0.0.1:{w.port}") for w in webs],
                f"ipv4@127.0.0.1:{stats}",
                tls=False,
            )
        )
        with (tmp_path / "haproxy.out").open("wb") as out:
            haproxy = subprocess.Popen([HAPROXY, "-f", str(config), "-db"], stdout=out,
                                       stderr=subprocess.STDOUT)  # fmt: skip
        front = Front(port)

        async def answers() -> bool:
            try:
                async with (
                    aiohttp.ClientSession() as session,
                    session.get(f"{front.url}/login") as answer,
                ):
                    return answer.status == 200
            except aiohttp.ClientError:
                return False

        await eventually(answers, "HAProxy passing the login page on")
        browser = Browser(front)  # type: ignore[arg-type]
        assert (await browser.login("ann")).url.path == "/"
        server = next(c.value for c in browser.session.cookie_jar if c.key == "workbench_server")
        status, said = await browser.upload("prog.viple", PROGRAM)
        assert status == 200, said
        page = await browser.page()
        await page.wait_for("Who is at this robot?", timeout=90)
        # a reload sticks to the same server: the same app, no second login there
        await page.close()
        again = await browser.page()
        await again.wait_for("Who is at this robot?", timeout=30)
        lost = next(w for w in webs if w.name == server)
        other = next(w for w in webs if w.name != server)
        assert "login: ann" in lost.log() and "login: ann" not in other.log()

        helpers = lost.helpers()
        lost.process.send_signal(signal.SIGKILL)
        lost.process.wait()
        end_left_over(helpers)
        await again.closed(timeout=30)

        # the next page goes to the other server, which asks for a login first
        async def refused_there() -> bool:
            try:
                socket = await browser.page()
            except aiohttp.WSServerHandshakeError as exc:
                return exc.status == 403
            await socket.close()
            return False

        await eventually(refused_there, "the other server asking for a login")
        assert (await browser.login("ann")).url.path == "/"
        fresh = await browser.page()
        await fresh.wait_for("Who is at this robot?", timeout=90)
        assert (workspace_folder(other.data_dir, "ann") / "prog.viple").read_bytes() == PROGRAM
        await fresh.close()
        await browser.close()
    finally:
        if haproxy is not None:
            stop(haproxy)
        for web in webs:
            helpers = web.helpers()
            stop(web.process)
            end_left_over(helpers)
