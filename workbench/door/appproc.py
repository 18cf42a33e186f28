"""One workbench app process per SSH session, spoken to in Textual's web-driver packets.

The process runs the workbench app with the web driver: its screen output arrives as ``D``
packets on its standard output, keys and resizes go in as packets on its standard input (see
:mod:`.packets`). It is forked by the fork server (:mod:`.forkserver`) when one runs, else
started as ``python -m workbench``. It runs in its own process group so that ending a session
ends the app and anything it started.
"""

from __future__ import annotations

import asyncio
import contextlib
import json
import logging
import os
import signal
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

from workbench.control.recording import RecordQuota
from workbench.files.workspace_files import UploadLimits
from workbench.wire import packets
from workbench.wire.settings import AppSettings

from .applog import AppLog, ErrorPipe, read_errors

if TYPE_CHECKING:
    from .forkserver import ForkedApp, ForkServer

log = logging.getLogger("workbench.ssh")

#: Textual's web driver, with an input thread that sleeps while no key comes
DRIVER = "workbench.tui.serving.terminal_driver:ServedTerminalDriver"
#: what the terminal is set back to when an app ends (the web driver leaves it to the server)
RESTORE_TERMINAL = (
    b"\x1b[?1000l\x1b[?1003l\x1b[?1015l\x1b[?1006l"  # mouse reporting off
    b"\x1b[?2004l"  # bracketed paste off
    b"\x1b[0m\x1b[?25h"  # plain text, cursor shown
    b"\x1b[?1049l"  # back from the alternate screen
)
READ_SIZE = 65536
#: how an app that ran out of memory says so on its error output (Python, the C library)
OUT_OF_MEMORY = (b"MemoryError", b"Cannot allocate memory", b"std::bad_alloc")


@dataclass(frozen=True)
class AppEntry:
    """How the lab server starts a session's app, handed down by the command that starts the
    server (the server itself knows no app)."""

    #: the command that starts the app as a new process; the app's settings follow it, as one
    #: JSON argument
    command: tuple[str, ...]
    #: the same app as a function for the fork server: ``module:function`` taking the
    #: settings (a JSON object)
    main: str
    #: modules the fork server imports before it forks (the app's own), and functions
    #: (``module:function``) it calls once they are imported
    preload: tuple[str, ...] = ()
    #: the app as a spare for the fork server to start ahead (``workbench/door/spares.py``):
    #: ``module:function`` taking the settings every session shares and a control socket
    #: ("": the app has no spares)
    spare: str = ""


@dataclass(frozen=True)
class AppSpec:
    """What one session's app is started with."""

    user: str
    role: str
    tcp_port: int
    ws_port: int
    hint: str
    data_dir: Path
    record_dir: Path
    #: the student's own folder: the app opens and saves files only there (and bundled ones)
    workspace: Path
    width: int = 80
    height: int = 24
    term: str = "xterm-256color"
    #: how much room the app's run records may take (the folder counted: the workspace's runs)
    record_quota: RecordQuota = field(default_factory=RecordQuota)
    #: what the student may keep in the workspace: the file server's limits, the app's too
    uploads: UploadLimits = field(default_factory=UploadLimits)

    def argv(self, command: tuple[str, ...]) -> list[str]:
        """The command line of the app as a new process: its settings as one JSON argument."""
        return [*command, json.dumps(self.settings().to_json())]

    def settings(self) -> AppSettings:
        """The app's settings: the login name is the student's (the partner is asked for),
        the VIPLE endpoints are the session's ports (the WebSocket one once the student asks
        for it), and files are opened and saved in the student's workspace only."""
        return AppSettings(
            student=self.user,
            ask_names=True,
            student_fixed=True,
            role=self.role,
            tcp_port=self.tcp_port,
            ws_url=f"ws://127.0.0.1:{self.ws_port}/",
            ws_at_start=False,
            connect_hint=self.hint,
            data_dir=Path(self.data_dir),
            record_dir=Path(self.record_dir),
            workspace=Path(self.workspace),
            record_cap=self.record_quota.record,
            runs_quota=self.record_quota.runs,
            runs_counted=Path(self.workspace) / "runs",
            upload_cap=self.uploads.file_size,
            workspace_quota=self.uploads.quota_bytes,
            workspace_files=self.uploads.quota_files,
        )

    def env(self, base: dict[str, str] | None = None) -> dict[str, str]:
        env = app_env(base)
        env.update(
            COLUMNS=str(self.width),
            ROWS=str(self.height),
            TERM=self.term or "xterm-256color",
        )
        return env


def spare_template(
    data_dir: Path,
    record_quota: RecordQuota,
    uploads: UploadLimits,
) -> tuple[dict[str, object], dict[str, str]]:
    """The settings and environment a student's session has before it is anybody's (what
    is each session's own, ``SESSION_FIELDS``, is the spare's to take): a spare app's."""
    spec = AppSpec("student", "student", 0, 0, "", data_dir, data_dir, data_dir,
                   record_quota=record_quota, uploads=uploads)  # fmt: skip
    return spec.settings().to_json(), spec.env()


def keep_spares(
    forkserver: ForkServer,
    count: int,
    app: AppEntry,
    data_dir: Path,
    record_quota: RecordQuota,
    uploads: UploadLimits,
) -> None:
    """Have ``forkserver`` keep ``count`` students' apps started ahead (none when the app has
    no spare entry), and say so in the log."""
    if count <= 0:
        return
    if not app.spare:
        log.warning("--spare-apps %d: this app has no spares; each session's app is forked", count)
        return
    from workbench.wire.settings import SESSION_FIELDS

    from .forkserver import ForkServerError

    settings, env = spare_template(data_dir, record_quota, uploads)
    try:
        forkserver.keep_spares(count, app.spare, settings, env, SESSION_FIELDS)
    except ForkServerError as exc:
        log.error("no spare apps: %s", exc)
        return
    log.info("the fork server keeps %d students' apps started ahead of their sessions", count)


def app_env(base: dict[str, str] | None = None) -> dict[str, str]:
    """The environment every app shares: the server's, without its terminal and Textual
    settings, with the web driver (also the fork server's, which imports Textual with it)."""
    env = {
        k: v
        for k, v in (os.environ if base is None else base).items()
        if not k.startswith(("TEXTUAL", "SSH_", "COLUMNS", "LINES", "ROWS"))
    }
    env.update(TEXTUAL_DRIVER=DRIVER, LANG=env.get("LANG") or "C.UTF-8")
    return env


def forward_hint(user: str, host: str, ssh_port: int, tcp_port: int, ws_port: int) -> str:
    """The one line that tells a student how their VIPLE reaches their robot."""
    port = "" if ssh_port == 22 else f"-p {ssh_port} "
    return (
        f"VIPLE: on your computer run  ssh -N {port}-L 1350:localhost:{tcp_port} "
        f"-R {ws_port}:localhost:8124 {user}@{host}  then VIPLE uses localhost:1350"
    )


class AppProcess:
    """A running app: feed it keys and sizes, receive its screen output, stop it for sure."""

    def __init__(
        self,
        argv: list[str],
        env: dict[str, str],
        log_path: Path,
        on_output: Callable[[bytes], None],
        *,
        forkserver: ForkServer | None = None,
        settings: dict[str, object] | None = None,
        memory: int = 0,
        log_size: int = 0,
    ) -> None:
        """``argv`` starts the app as a new process; with a running ``forkserver`` the app is
        forked from it with ``settings`` (a JSON object) instead (``argv`` stays the way if
        that fails). The app may have ``memory`` bytes (0: no cap). Its error output goes to
        ``log_path``, of at most ``log_size`` bytes rotated once (0: no cap)."""
        self.argv = argv
        self.env = env
        self.log_path = log_path
        self.errors = AppLog(log_path, log_size)
        self._error_pipe: ErrorPipe | None = None
        self.on_output = on_output
        self.forkserver = forkserver
        self.settings = settings
        self.memory = memory
        self.forked = False
        self.process: asyncio.subprocess.Process | ForkedApp | None = None
        self.said_exit = False  # the app announced its end itself
        self._flowing = asyncio.Event()
        self._flowing.set()
        self._reader: asyncio.Task[None] | None = None
        self._pending: list[bytes] = []

    @property
    def pid(self) -> int | None:
        return self.process.pid if self.process else None

    @property
    def returncode(self) -> int | None:
        return self.process.returncode if self.process else None

    async def start(self) -> None:
        # the app writes its error output into a pipe the server reads as it comes
        errors_r, errors_w = os.pipe2(os.O_CLOEXEC)
        try:
            self._error_pipe = await read_errors(self.errors, errors_r)
        except BaseException:
            os.close(errors_w)
            raise
        try:
            await self._spawn(errors_w)
        except BaseException:
            self._error_pipe.close()
            self.errors.close()
            raise
        finally:
            os.close(errors_w)  # the app holds its own copy
        for packet in self._pending:
            self._write(packet)
        self._pending.clear()
        self._reader = asyncio.create_task(self._read(), name=f"app-output-{self.pid}")

    async def _spawn(self, errors: int) -> None:
        forkserver = self.forkserver
        if forkserver is not None and forkserver.running and self.settings is not None:
            from .forkserver import ForkServerError

            try:
                self.process = await forkserver.spawn(
                    self.settings, self.env, errors, memory=self.memory
                )
                self.forked = True
            except ForkServerError as exc:
                log.warning("app not forked (%s): starting it as a new process", exc)
        if self.process is None:
            self.process = await asyncio.create_subprocess_exec(
                *self.argv,
                stdin=asyncio.subprocess.PIPE,
                stdout=asyncio.subprocess.PIPE,
                stderr=errors,
                env=self.env,
                start_new_session=True,
            )
            from .forkserver import APP_NICENESS, limit_memory, lower_priority

            lower_priority(APP_NICENESS, self.process.pid)  # as a forked app runs
            limit_memory(self.memory, self.process.pid)

    # -- input -------------------------------------------------------------------------------
    def _write(self, packet: bytes) -> None:
        process = self.process
        if process is None:
            self._pending.append(packet)
            return
        if process.stdin is None or process.stdin.is_closing():
            return
        with contextlib.suppress(BrokenPipeError, ConnectionResetError):
            process.stdin.write(packet)

    def send_keys(self, data: bytes) -> None:
        if data:
            self._write(packets.data(data))

    def resize(self, width: int, height: int) -> None:
        if width > 0 and height > 0:
            self._write(packets.resize(width, height))

    def redraw(self) -> None:
        """Ask the app for its whole screen again (a new terminal shows it)."""
        self._write(packets.redraw())

    # -- output ------------------------------------------------------------------------------
    def pause_output(self) -> None:
        """Stop reading the app's screen output (the client is behind); the app then waits."""
        self._flowing.clear()

    def resume_output(self) -> None:
        self._flowing.set()

    async def _read(self) -> None:
        assert self.process is not None and self.process.stdout is not None
        stdout = self.process.stdout
        reader = packets.PacketReader()
        try:
            while True:
                await self._flowing.wait()
                chunk = await stdout.read(READ_SIZE)
                if not chunk:
                    break
                # the screen output of one read goes on as one piece (one write to the
                # client's channel, one SSH packet), however many packets it came in
                screen: list[bytes] = []
                for kind, payload in reader.feed(chunk):
                    if kind == packets.DATA:
                        screen.append(payload)
                    elif kind == packets.META:
                        if screen:
                            self.on_output(b"".join(screen))
                            screen.clear()
                        self._on_meta(payload)
                if screen:
                    self.on_output(b"".join(screen))
        except packets.PacketError as exc:
            log.error("app %s: %s; ending it", self.pid, exc)
            self._kill(signal.SIGKILL)
        if reader.preamble.strip():
            log.info("app %s printed before starting: %r", self.pid, reader.preamble[:200])

    def _on_meta(self, payload: bytes) -> None:
        try:
            message = json.loads(payload)
        except ValueError:
            return
        if isinstance(message, dict) and message.get("type") == "exit":
            self.said_exit = True

    # -- the end -----------------------------------------------------------------------------
    async def wait(self) -> int:
        """The exit code, once the app has ended and all its output was handed on."""
        assert self.process is not None
        if self._reader is not None:
            await self._reader
        code = await self.process.wait()
        self._close_input()
        await self._end_errors()
        if not getattr(self.process, "status_known", True) and self.said_exit:
            code = 0  # its fork server was lost, but the app said it ended by itself
        return code

    async def _end_errors(self, grace: float = 1.0) -> None:
        """Read the app's last error output and close its log. What the app started may
        still hold the pipe: it is read for ``grace`` seconds more, then closed."""
        pipe = self._error_pipe
        if pipe is not None:
            with contextlib.suppress(TimeoutError):
                await asyncio.wait_for(asyncio.shield(pipe.done), grace)
            pipe.close()
        self.errors.close()

    def ran_out_of_memory(self) -> bool:
        """Whether the app, ended with an error, says on its error output that memory ran out
        (under its cap, an allocation past it fails)."""
        if self.memory <= 0 or not self.returncode:
            return False
        return any(sign in self.errors.tail for sign in OUT_OF_MEMORY)

    def _close_input(self) -> None:
        process = self.process
        if process is not None and process.stdin is not None:
            process.stdin.close()

    def _kill(self, sig: int) -> None:
        process = self.process
        if process is None or process.returncode is not None:
            return
        with contextlib.suppress(ProcessLookupError, PermissionError):
            os.killpg(process.pid, sig)

    async def stop(self, grace: float = 2.0) -> int | None:
        """End the app: ask it to quit, then SIGTERM its group, then SIGKILL; always reaped."""
        process = self.process
        if process is None:
            return None
        self._flowing.set()  # a paused reader must not hold the end up
        if process.returncode is None:
            self._write(packets.quit_message())
            for sig in (signal.SIGTERM, signal.SIGKILL):
                try:
                    await asyncio.wait_for(asyncio.shield(process.wait()), grace)
                    break
                except TimeoutError:
                    log.info(
                        "app %s did not end in %.1f s: sending %s",
                        process.pid,
                        grace,
                        signal.Signals(sig).name,
                    )
                    self._kill(sig)
        code = await process.wait()
        self._close_input()
        if self._reader is not None:
            with contextlib.suppress(Exception):
                await asyncio.wait_for(self._reader, grace)
        await self._end_errors()
        return code
