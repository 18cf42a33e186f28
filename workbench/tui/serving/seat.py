"""A spare app's wait for its session, and its taking of it.

The lab server's fork server may start apps before their students come
(``workbench/door/spares.py``): such a spare runs to the names dialog with no terminal and
waits. Its :class:`Seat` watches the spare's control socket on the app's event loop; the
session comes as one message on it, with two descriptors: the session's socket (the app's
terminal from then on, its standard input and output) and its error output. The seat puts the
session's environment, folder and descriptors in place, hands the terminal to the driver
(:meth:`ServedTerminalDriver.take_terminal`: the app's start announced on it, the terminal's
size, the whole screen drawn) and the settings to the app (``take_seat``), whose session then
starts as a new app's would. A control socket that closes with no session (the fork server
stopping) ends the process at once: a spare has nothing of anyone's to save.
"""

from __future__ import annotations

import contextlib
import json
import os
import socket
import sys
from collections.abc import Callable
from typing import Any

from textual.app import App

from workbench.wire.settings import AppSettings, SettingsError

from .terminal_driver import ServedTerminalDriver

#: the largest session message taken
MAX_MESSAGE = 1 << 20


class Seat:
    """Waits on a spare's control socket for its session."""

    def __init__(
        self,
        control: socket.socket,
        complete: Callable[[AppSettings], AppSettings] | None = None,
    ) -> None:
        """``complete(settings)`` fills in what the session's settings leave to the app's
        environment (the course database's URL)."""
        self.control = control
        self.control.setblocking(False)
        self._complete = complete
        self._app: App[Any] | None = None

    def wait(self, app: App[Any]) -> None:
        """Watch for the session on ``app``'s loop (from the app's mount on)."""
        import asyncio

        self._app = app
        asyncio.get_running_loop().add_reader(self.control.fileno(), self._arrived)

    def _arrived(self) -> None:
        import asyncio

        app = self._app
        assert app is not None
        try:
            message, fds, _, _ = socket.recv_fds(self.control, MAX_MESSAGE, 4)
        except (BlockingIOError, InterruptedError):
            return
        except OSError:
            message, fds = b"", []
        asyncio.get_running_loop().remove_reader(self.control.fileno())
        self.control.close()
        if not message or len(fds) != 2:
            # the fork server stopped: no student will come, and a spare holds nothing of
            # anyone's, so it ends at once (an exit in the middle of its start would leave
            # its names dialog half mounted and a traceback in the server's log)
            os._exit(0)
        io, errors = fds
        os.dup2(errors, 2)
        os.close(errors)
        try:
            request = json.loads(message)
            env = {str(k): str(v) for k, v in request["env"].items()}
            settings = AppSettings.from_json(request["settings"])
        except (ValueError, KeyError, TypeError, AttributeError, SettingsError) as exc:
            print(f"workbench: this session's settings cannot be used: {exc}", file=sys.stderr)
            os.close(io)
            app.exit(return_code=2)
            return
        os.environ.clear()
        os.environ.update(env)
        cwd = request.get("cwd")
        if isinstance(cwd, str) and cwd:
            with contextlib.suppress(OSError):
                os.chdir(cwd)
        try:
            if self._complete is not None:
                settings = self._complete(settings)
        except Exception as exc:  # the database's URL in the environment, say
            print(f"workbench: {exc}", file=sys.stderr)
            os.close(io)
            app.exit(return_code=2)
            return
        app.call_later(self._take, app, settings, io, _size(env))

    async def _take(
        self, app: App[Any], settings: AppSettings, io: int, size: tuple[int, int]
    ) -> None:
        """The app takes its session's settings (its screen still drawn for nobody), then
        its terminal: the student's first screen is the whole of it, with their name."""
        try:
            await app.take_seat(settings)  # type: ignore[attr-defined]
            driver = app._driver
            if app.return_code is None and isinstance(driver, ServedTerminalDriver):
                driver.take_terminal(io, size)
        finally:
            os.close(io)


def _size(env: dict[str, str]) -> tuple[int, int]:
    try:
        return max(1, int(env.get("COLUMNS", 80))), max(1, int(env.get("ROWS", 24)))
    except ValueError:
        return 80, 24
