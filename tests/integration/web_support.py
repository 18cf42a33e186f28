"""What the browser door's tests share: a server on loopback with a throwaway data folder and
the accounts of ``ssh_support``, and a browser's part played by aiohttp's client: the login
form, the cookie jar, the page's WebSocket whose screen bytes pyte reads (the terminal of
``ssh_support`` with a WebSocket under it, so its waits and the lab helpers drive either)."""

from __future__ import annotations

import asyncio
import contextlib
import json
import re
from collections.abc import AsyncIterator
from dataclasses import dataclass, field
from pathlib import Path

import aiohttp
import pyte
import yarl

from workbench.cli.ssh import WORKBENCH_APP
from workbench.door.limits import SessionLimits
from workbench.door.logins import LoginPolicy
from workbench.web.config import WebConfig
from workbench.web.server import WebServer

from .ssh_support import Account, Terminal, make_accounts, port_range

PASSWORD = "lab-password-1"
_CSRF = re.compile(r'name="csrf" value="([^"]+)"')


@dataclass
class WebHost:
    server: WebServer
    data_dir: Path
    accounts: dict[str, Account] = field(default_factory=dict)

    @property
    def url(self) -> str:
        scheme = "https" if self.server.config.tls else "http"
        return f"{scheme}://127.0.0.1:{self.server.port}"

    def browser(self, **options) -> Browser:
        return Browser(self, **options)


class Browser:
    """One browser: its own cookies; log in, open the page's WebSocket, send files."""

    def __init__(self, host: WebHost, headers: dict[str, str] | None = None) -> None:
        self.host = host
        self.session = aiohttp.ClientSession(
            cookie_jar=aiohttp.CookieJar(unsafe=True),
            headers=headers or {},
            connector=aiohttp.TCPConnector(ssl=False),  # the tests' own certificate
        )
        self.csrf = ""

    async def login(self, name: str, password: str = PASSWORD) -> aiohttp.ClientResponse:
        """Fill in and send the login form; the answer (the page after it, or the form
        again with why)."""
        async with self.session.get(f"{self.host.url}/login") as form:
            token = _CSRF.search(await form.text())
        assert token, "no form token on the login page"
        answer = await self.session.post(
            f"{self.host.url}/login",
            data={"csrf": token.group(1), "user": name, "password": password},
            headers={"Origin": self.host.url},
        )
        page = await answer.text()
        found = re.search(r'data-csrf="([^"]+)"', page)
        self.csrf = found.group(1) if found else ""
        return answer

    async def page(self, size: tuple[int, int] = (80, 24), origin: str | None = None
                   ) -> WebTerminal:  # fmt: skip
        """Open the terminal page's WebSocket, as the page's script does."""
        socket = await self.session.ws_connect(
            f"{self.host.url}/ws?cols={size[0]}&rows={size[1]}",
            origin=origin or self.host.url,
            max_msg_size=0,
        )
        return WebTerminal(socket, size)

    async def upload(
        self, name: str, data: bytes, *, folder: str = "", csrf: str | None = None
    ) -> tuple[int, dict]:
        """Send a file with the files panel's form (into ``folder``); the status and the
        JSON answer."""
        form = aiohttp.FormData()
        form.add_field("csrf", self.csrf if csrf is None else csrf)
        form.add_field("folder", folder)
        form.add_field("file", data, filename=name, content_type="application/octet-stream")
        async with self.session.post(
            f"{self.host.url}/files", data=form, headers={"Origin": self.host.url}
        ) as answer:
            return answer.status, await answer.json()

    async def get(self, path: str) -> tuple[int, bytes]:
        """GET ``path`` as written (its dots and escapes kept, as an attacker sends them)."""
        url = yarl.URL(f"{self.host.url}{path}", encoded=True)
        async with self.session.get(url) as answer:
            return answer.status, await answer.read()

    async def close(self) -> None:
        await self.session.close()


class WebTerminal(Terminal):
    """The page's terminal: screen bytes from the WebSocket into pyte; notices kept."""

    def __init__(self, socket: aiohttp.ClientWebSocketResponse, size: tuple[int, int]):
        self.socket = socket
        self.screen = pyte.Screen(*size)
        self.stream = pyte.ByteStream(self.screen)
        self.raw = bytearray()
        self.notices: list[dict] = []
        self._changed = asyncio.Event()
        self._reader = asyncio.create_task(self._read())

    async def _read(self) -> None:  # type: ignore[override]
        async for message in self.socket:
            if message.type == aiohttp.WSMsgType.BINARY:
                self.raw += message.data
                self.stream.feed(message.data)
            elif message.type == aiohttp.WSMsgType.TEXT:
                self.notices.append(json.loads(message.data))
            self._changed.set()
        self._changed.set()

    def send(self, keys: str) -> None:
        asyncio.get_running_loop().create_task(self.socket.send_bytes(keys.encode()))

    def resize(self, width: int, height: int) -> None:
        said = json.dumps({"type": "resize", "cols": width, "rows": height})
        asyncio.get_running_loop().create_task(self.socket.send_str(said))
        self.screen.resize(height, width)

    async def closed(self, timeout: float = 10.0) -> None:
        await asyncio.wait_for(asyncio.shield(self._reader), timeout)

    async def close(self) -> None:
        await self.socket.close()
        with contextlib.suppress(Exception):
            await asyncio.wait_for(self._reader, 5)


@contextlib.asynccontextmanager
async def web_host(
    tmp_path: Path,
    accounts: list[Account],
    limits: SessionLimits | None = None,
    **config,
) -> AsyncIterator[WebHost]:
    data_dir = tmp_path / "data"
    made = make_accounts(data_dir, accounts)
    server = WebServer(
        WebConfig(
            data_dir=data_dir,
            port=0,
            bind="127.0.0.1",
            port_range=port_range(),
            app=config.pop("app", WORKBENCH_APP),
            limits=limits or SessionLimits(),
            **({"logins": LoginPolicy(first_delay=0.05, max_delay=0.2)} | config),
        )
    )
    await server.start()
    try:
        yield WebHost(server, data_dir, made)
    finally:
        await server.close()
