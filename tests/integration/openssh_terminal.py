"""OpenSSH's own client on a pty (``ssh -tt``), as a student or an instructor logs in, its
output fed into an emulated 80x24 screen. Its reads block, so a test running the lab server on
its event loop waits through a thread (:meth:`OpenSshTerminal.wait_until` is async). It answers
the calls of the asyncssh terminal in ``ssh_support`` that the lab helpers use (``send``,
``wait_for``, ``wait_until``, ``start_app``), so ``open_exercise`` drives either."""

from __future__ import annotations

import asyncio
import os
import time
from collections.abc import Callable
from pathlib import Path
from typing import Protocol

import pexpect
import pyte

SIZE = (24, 80)


class Screen(Protocol):
    """A terminal a test types into and reads (either client)."""

    def send(self, keys: str) -> None: ...

    async def wait_for(self, *needles: str, timeout: float = ...) -> str: ...

    async def wait_until(
        self, check: Callable[[str], bool], what: str, timeout: float = ...
    ) -> str: ...


async def pass_the_names(term: Screen) -> str:
    """Pass a new session's names dialog with Enter; the app's main screen."""
    # an app started as a new process imports all of Textual afresh: slow on a busy machine
    await term.wait_for("Who is at this robot?", "Partner", timeout=90)
    term.send("\r")
    return await term.wait_until(
        lambda t: "Who is at this robot?" not in t and "distance 0.00 unit" in t,
        "the main screen",
    )


class OpenSshTerminal:
    def __init__(self, user: str, port: int, key: Path) -> None:
        self.screen = pyte.Screen(SIZE[1], SIZE[0])
        self.stream = pyte.ByteStream(self.screen)
        argv = [
            "-tt", "-F", "/dev/null", "-i", str(key), "-p", str(port),
            "-o", "StrictHostKeyChecking=no", "-o", "UserKnownHostsFile=/dev/null",
            "-o", "BatchMode=yes", f"{user}@127.0.0.1",
        ]  # fmt: skip
        env = {k: v for k, v in os.environ.items() if not k.startswith(("TEXTUAL", "SSH_"))}
        env.update(TERM="xterm-256color", LANG="C.UTF-8")
        self.child = pexpect.spawn("ssh", argv, env=env, dimensions=SIZE)

    def text(self) -> str:
        return "\n".join(self.screen.display)

    def _wait(self, check: Callable[[str], bool], what: str, timeout: float) -> str:
        end = time.monotonic() + timeout
        while time.monotonic() < end:
            try:
                self.stream.feed(self.child.read_nonblocking(65536, timeout=0.05))
            except pexpect.TIMEOUT:
                pass
            except pexpect.EOF:
                break
            if check(self.text()):
                return self.text()
        raise AssertionError(f"{what}: not on the screen after {timeout} s:\n{self.text()}")

    async def wait_until(
        self, check: Callable[[str], bool], what: str, timeout: float = 30.0
    ) -> str:
        return await asyncio.to_thread(self._wait, check, what, timeout)

    async def wait_for(self, *needles: str, timeout: float = 30.0) -> str:
        return await self.wait_until(
            lambda text: all(n in text for n in needles), f"{list(needles)}", timeout
        )

    async def start_app(self) -> str:
        """Pass the names dialog with Enter; the app's main screen."""
        return await pass_the_names(self)

    def send(self, keys: str) -> None:
        self.child.send(keys)

    def close(self) -> None:
        self.child.terminate(force=True)
