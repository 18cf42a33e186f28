"""What the SSH lab server tests share: a server on loopback with a throwaway data folder,
users made with the users module, and an SSH client with a pty whose screen is read by pyte."""

from __future__ import annotations

import asyncio
import contextlib
import os
import random
import time
from collections.abc import AsyncIterator, Callable
from dataclasses import dataclass, field
from pathlib import Path

import asyncssh
import pyte

from workbench.cli.ssh import WORKBENCH_APP
from workbench.door.limits import SessionLimits
from workbench.door.logins import LoginPolicy
from workbench.door.passwords import hash_password
from workbench.door.users import add_user, users_path
from workbench.ssh.server import LabServer, ServerConfig

from .openssh_terminal import pass_the_names

PASSWORD = "lab-password-1"


@dataclass
class Account:
    name: str
    role: str = "student"
    key: asyncssh.SSHKey | None = None
    password: str | None = None


@dataclass
class LabHost:
    """A running lab server and the accounts made for it."""

    server: LabServer
    data_dir: Path
    accounts: dict[str, Account] = field(default_factory=dict)

    @property
    def port(self) -> int:
        return self.server.port

    async def connect(
        self, name: str, *, password: str | None = None, key: bool = True, **options
    ) -> asyncssh.SSHClientConnection:
        account = self.accounts.get(name)
        keys = [account.key] if key and account is not None and account.key else []
        options = {"agent_path": None} | options
        return await asyncssh.connect(
            "127.0.0.1",
            self.port,
            username=name,
            client_keys=keys,
            password=password,
            known_hosts=None,
            preferred_auth=["publickey", "password"] if keys else ["password"],
            **options,
        )

    async def terminal(self, name: str, size: tuple[int, int] = (80, 24), **kw) -> Terminal:
        conn = await self.connect(name, **kw)
        return await Terminal.open(conn, size)


def make_accounts(data_dir: Path, accounts: list[Account]) -> dict[str, Account]:
    """Write the users file with each account's public key and password hash."""
    path = users_path(data_dir)
    for account in accounts:
        if account.key is None and account.password is None:
            account.key = asyncssh.generate_private_key("ssh-ed25519")
        keys = [account.key.export_public_key().decode()] if account.key else []
        hashed = hash_password(account.password) if account.password else None
        add_user(path, account.name, account.role, keys, hashed)
    return {a.name: a for a in accounts}


def port_range(size: int = 60) -> tuple[int, int]:
    """A block of VIPLE ports unlikely to be in use by another test run."""
    first = random.randrange(42000, 60000 - size, size)
    return first, first + size - 1


@contextlib.asynccontextmanager
async def lab_host(
    tmp_path: Path,
    accounts: list[Account],
    limits: SessionLimits | None = None,
    **config,
) -> AsyncIterator[LabHost]:
    data_dir = tmp_path / "data"
    made = make_accounts(data_dir, accounts)
    server = LabServer(
        ServerConfig(
            data_dir=data_dir,
            port=0,
            bind="127.0.0.1",
            port_range=port_range(),
            public_host="lab.example",
            app=config.pop("app", WORKBENCH_APP),
            limits=limits or SessionLimits(),
            **({"logins": LoginPolicy(first_delay=0.05, max_delay=0.2)} | config),
        )
    )
    await server.start()
    try:
        yield LabHost(server, data_dir, made)
    finally:
        await server.close()


class Terminal:
    """An SSH session with a pty; what the app draws is fed into a pyte screen."""

    def __init__(self, conn: asyncssh.SSHClientConnection, process, size: tuple[int, int]):
        self.conn = conn
        self.process = process
        self.screen = pyte.Screen(*size)
        self.stream = pyte.ByteStream(self.screen)
        self.raw = bytearray()
        self._changed = asyncio.Event()
        self._reader = asyncio.create_task(self._read())

    @classmethod
    async def open(cls, conn: asyncssh.SSHClientConnection, size: tuple[int, int]) -> Terminal:
        process = await conn.create_process(
            term_type="xterm-256color", term_size=size, encoding=None
        )
        return cls(conn, process, size)

    async def _read(self) -> None:
        while True:
            chunk = await self.process.stdout.read(65536)
            if not chunk:
                self._changed.set()
                return
            self.raw += chunk
            self.stream.feed(chunk)
            self._changed.set()

    @property
    def ended(self) -> bool:
        return self._reader.done()

    def text(self) -> str:
        return "\n".join(self.screen.display)

    async def wait_until(
        self, check: Callable[[str], bool], what: str, timeout: float = 20.0
    ) -> str:
        deadline = time.monotonic() + timeout
        while True:
            text = self.text()
            if check(text):
                return text
            left = deadline - time.monotonic()
            if left <= 0 or self.ended:
                raise AssertionError(f"{what}: not on the screen after {timeout} s:\n{text}")
            self._changed.clear()
            with contextlib.suppress(TimeoutError):
                await asyncio.wait_for(self._changed.wait(), min(left, 0.25))

    async def wait_for(self, *needles: str, timeout: float = 20.0) -> str:
        return await self.wait_until(
            lambda text: all(n in text for n in needles), f"{list(needles)}", timeout
        )

    async def wait_gone(self, needle: str, timeout: float = 10.0) -> str:
        return await self.wait_until(lambda text: needle not in text, f"no {needle!r}", timeout)

    def send(self, keys: str) -> None:
        self.process.stdin.write(keys.encode())

    async def start_app(self) -> str:
        """Pass the names dialog with Enter; the app's main screen."""
        return await pass_the_names(self)

    def resize(self, width: int, height: int) -> None:
        self.process.change_terminal_size(width, height)
        self.screen.resize(height, width)

    async def exit_status(self, timeout: float = 10.0) -> int | None:
        await asyncio.wait_for(self.process.wait_closed(), timeout)
        return self.process.exit_status

    async def close(self) -> None:
        self.conn.close()
        with contextlib.suppress(Exception):
            await asyncio.wait_for(self.conn.wait_closed(), 5)
        self._reader.cancel()


def line_with(text: str, needle: str) -> str:
    return next((line for line in text.splitlines() if needle in line), "")


def distance(text: str) -> str:
    """The run panel's distance, e.g. ``"1.45 unit"`` ("" when not on the screen)."""
    for line in text.splitlines():
        words = line.split()
        if len(words) >= 3 and words[0] == "distance" and words[2] == "unit":
            return f"{words[1]} unit"
    return ""


def moved(text: str) -> bool:
    return distance(text) not in ("", "0.00 unit")


async def open_exercise(term: Terminal, title: str, presses: int = 20) -> str:
    """Open the labs (``l``) and move down the list until ``title`` is the exercise shown."""
    term.send("l")
    await term.wait_for("esc Back", "r Ready")
    screen = await term.wait_until(lambda t: "loading saved work" not in t, "the saved work read")
    for _ in range(presses):
        if title in screen.splitlines()[0]:
            return screen
        before = screen.splitlines()[0]
        term.send("\x1b[B")  # down
        screen = await term.wait_until(
            lambda t, before=before: t.splitlines()[0] != before, "the next exercise"
        )
    raise AssertionError(f"{title!r} not found in the labs list:\n{screen}")


class BareChannel(asyncssh.SSHClientSession[bytes]):
    """The client's side of a session channel that asks for nothing: what the server writes
    on it, and whether it was closed."""

    def __init__(self) -> None:
        self.said = bytearray()
        self.closed = asyncio.Event()

    def data_received(self, data: bytes, datatype: asyncssh.DataType) -> None:
        self.said += data

    def connection_lost(self, exc: Exception | None) -> None:
        self.closed.set()


async def open_bare_channel(
    conn: asyncssh.SSHClientConnection,
) -> tuple[asyncssh.SSHClientChannel[bytes], BareChannel]:
    """Open a session channel and ask for nothing on it (no terminal, command or subsystem),
    as an attacker would: asyncssh's client always asks for something, so this opens the
    channel the way its ``create_session`` does and stops there. Raises
    :class:`asyncssh.ChannelOpenError` when the server refuses the channel."""
    chan: asyncssh.SSHClientChannel[bytes] = asyncssh.SSHClientChannel(
        conn, asyncio.get_running_loop(), "strict", None, "strict", 2 * 1024 * 1024, 32768
    )
    packet = await chan._open(b"session")
    packet.check_end()
    session = BareChannel()
    chan._session = session
    session.connection_made(chan)
    chan.resume_reading()  # a new channel holds what it receives until it is started
    return chan, session


def gone(pid: int) -> bool:
    """Whether no process ``pid`` is left (a zombie, not yet reaped, would still answer)."""
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return True
    return False


async def idle_socket(port: int, address: str = "127.0.0.1"):
    """A connection from ``address`` that never says a word."""
    return await asyncio.open_connection("127.0.0.1", port, local_addr=(address, 0))
