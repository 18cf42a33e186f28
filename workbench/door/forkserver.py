"""A fork server for session apps: one process that has imported the workbench once, forks
a copy of itself for each session, and so starts an app in a fraction of the time and memory
a fresh ``python -m workbench`` takes.

Two halves live here:

- the fork server process (``python -m workbench.door.forkserver FD MAIN [MODULE...]``): started
  by the lab server with the apps' environment and the app's entry point (``MAIN``, as
  ``module:function``, handed down by whoever starts the lab server), it imports the modules it
  is given, the :data:`PRELOAD` list and every module of the workbench packages the app uses;
  then it calls each ``module:function`` among the modules given (work every app would do the
  same way, done once here: the app's is :func:`workbench.tui.app.warm_up`), freezes it all
  out of the garbage collector's reach (so the pages stay shared with the children) and waits
  on a Unix socket.
  Each request carries the app's settings (a JSON object) and environment and two file
  descriptors (SCM_RIGHTS):
  the socket that becomes the app's standard input and output, and its error output (the
  pipe the lab server reads into the session's log, :mod:`.applog`). It forks; the
  child starts a new session (its own process group), puts the descriptors on 0, 1 and 2, sets
  the environment and runs the entry point with the app's settings, ending with the
  interpreter's ordinary exit. An app runs :data:`APP_NICENESS` steps below the lab server, so
  the server's own work (handshakes, logins, passing keys and screens on) goes first when a
  whole class arrives at once, and under the memory cap the request names
  (:func:`limit_memory`). The fork server answers with the child's pid, reaps children
  as they end and reports each one's exit status.
- :class:`ForkServer`, the lab server's side: starts that process, sends requests and turns the
  answers into :class:`ForkedApp` objects that look like an ``asyncio.subprocess.Process``
  (``pid``, ``returncode``, ``stdin``, ``stdout``, ``wait()``).

The fork server is a separate process started from scratch, not a fork of the lab server, so
its children inherit nothing of the server's event loop, asyncssh connections or threads.
"""

from __future__ import annotations

import asyncio
import collections
import contextlib
import gc
import importlib
import json
import logging
import os
import pkgutil
import random
import resource
import selectors
import signal
import socket
import sys
import threading
import time
from collections.abc import Callable
from pathlib import Path

from .spares import SparePool, SpareSpec, SpareSpecError

log = logging.getLogger("workbench.ssh")

#: modules the app imports, loaded once in the fork server
PRELOAD = ("textual.drivers.web_driver", "workbench.tui.serving.terminal_driver")
#: packages whose every module is loaded too (the app imports many of them only when used)
PRELOAD_PACKAGES = (
    "workbench.sim",
    "workbench.control",
    "workbench.viple",
    "workbench.labs",
    "workbench.wire",
    "workbench.tui",
)
MAX_MESSAGE = 1 << 20
#: how much lower an app's scheduling priority is than the lab server's (``nice``)
APP_NICENESS = 10
#: exit status given for an app whose status could not be learnt (the fork server was lost)
UNKNOWN_STATUS = 1
#: the limit an app's memory cap is set on: on Linux the data segment and private writable
#: mappings (the memory an app can fill, not the address space it only reserves, which grows
#: by tens of MB with each thread), elsewhere the address space
MEMORY_LIMIT = resource.RLIMIT_DATA if sys.platform == "linux" else resource.RLIMIT_AS


#: an app's exit status, None when it could not be learnt
Ended = asyncio.Future[int | None]


class ForkServerError(Exception):
    """The fork server cannot start an app (not running, or it refused)."""


# -- the fork server process -----------------------------------------------------------------
def _send(control: socket.socket, message: dict) -> None:
    with contextlib.suppress(OSError):
        control.send(json.dumps(message).encode())


def entry_point(main: str) -> Callable[..., int]:
    """The function named ``module:function``; ValueError when it is not one."""
    module, _, function = main.partition(":")
    if not module or not function:
        raise ValueError(f"the app's entry point must read module:function, not {main!r}")
    entry = vars(importlib.import_module(module)).get(function)
    if not callable(entry):
        raise ValueError(f"{main}: {module} has no function {function!r}")
    return entry


def preload(modules: tuple[str, ...] = ()) -> int:
    """Import what the app will import, then call each ``module:function`` of ``modules``; the
    number of modules loaded in all."""
    names = [name.partition(":")[0] for name in modules]
    for name in (*names, *PRELOAD):
        importlib.import_module(name)
    for package in PRELOAD_PACKAGES:
        path = importlib.import_module(package).__path__
        for info in pkgutil.walk_packages(path, package + "."):
            if info.name.rsplit(".", 1)[-1] == "__main__":
                continue
            try:
                importlib.import_module(info.name)
            except Exception as exc:  # the app itself will report it, if it uses the module
                print(f"fork server: not preloaded: {info.name}: {exc}", file=sys.stderr)
    for name in modules:
        if ":" in name:
            entry_point(name)()
    return len(sys.modules)


class _Zygote:
    """The fork server's loop: fork on request, reap and report the children's ends."""

    def __init__(self, control: socket.socket, main: Callable[[object], int]) -> None:
        self.control = control
        self.main = main
        #: apps started ahead of their sessions (once the lab server asks for them)
        self.spares: SparePool | None = None

    def serve(self) -> Callable[[], int] | None:
        """Serve until the lab server goes (``None``); in a forked child, return its app."""
        wake_r, wake_w = os.pipe2(os.O_NONBLOCK | os.O_CLOEXEC)
        signal.set_wakeup_fd(wake_w)
        signal.signal(signal.SIGCHLD, lambda *_: None)
        selector = selectors.DefaultSelector()
        selector.register(self.control, selectors.EVENT_READ)
        selector.register(wake_r, selectors.EVENT_READ)

        def child(app: Callable[[], int]) -> Callable[[], int]:
            selector.close()
            for fd in (wake_r, wake_w):
                os.close(fd)
            self.control.close()
            signal.set_wakeup_fd(-1)
            return app

        try:
            while True:
                spares = self.spares
                for key, _ in selector.select(None if spares is None else spares.wait_time()):
                    if key.fileobj is self.control:
                        message, fds, _, _ = socket.recv_fds(self.control, MAX_MESSAGE, 4)
                        if not message:
                            if self.spares is not None:
                                self.spares.close()
                            return None  # the lab server closed its end: stop
                        app = self._fork(message, fds)
                        if app is not None:  # this is the child
                            return child(app)
                    else:
                        with contextlib.suppress(BlockingIOError):
                            while os.read(wake_r, 512):
                                pass
                self._reap()
                if self.spares is not None and (app := self.spares.refill()) is not None:
                    return child(app)
        finally:
            with contextlib.suppress(ValueError, OSError):
                signal.signal(signal.SIGCHLD, signal.SIG_DFL)

    def _fork(self, message: bytes, fds: list[int]) -> Callable[[], int] | None:
        try:
            request = json.loads(message)
            if isinstance(request, dict) and "spares" in request:
                self._keep_spares(request["spares"], fds)
                return None
            settings = request["settings"]
            if not isinstance(settings, dict):
                raise TypeError("the settings are not a JSON object")
            env = {str(k): str(v) for k, v in request["env"].items()}
            memory = int(request.get("memory", 0))
            if len(fds) != 2:
                raise ValueError(f"{len(fds)} descriptors instead of 2")
        except (ValueError, KeyError, TypeError, AttributeError) as exc:
            for fd in fds:
                os.close(fd)
            _send(self.control, {"error": f"bad request: {exc}"})
            return None
        if self.spares is not None:
            spare = self.spares.take(request, fds, limit_memory)
            if spare is not None:
                for fd in fds:
                    os.close(fd)  # the spare has its own copies
                _send(self.control, {"pid": spare})
                return None
        ready_r, ready_w = os.pipe()
        try:
            pid = os.fork()
        except OSError as exc:
            for fd in (*fds, ready_r, ready_w):
                os.close(fd)
            _send(self.control, {"error": f"fork: {exc}"})
            return None
        if pid == 0:
            os.setsid()  # its own session and process group, before the server learns its pid
            os.close(ready_r)
            os.close(ready_w)
            if self.spares is not None:
                self.spares.close()  # (this copy's ends only: the spares are not the app's)
            return lambda: _run_app(self.main, settings, env, fds, request.get("cwd"), memory)
        for fd in (*fds, ready_w):
            os.close(fd)
        with contextlib.suppress(OSError):
            os.read(ready_r, 1)  # end of file once the child has its own process group
        os.close(ready_r)
        _send(self.control, {"pid": pid})
        return None

    def _keep_spares(self, message: object, fds: list[int]) -> None:
        for fd in fds:
            os.close(fd)
        try:
            spec = SpareSpec.from_message(message)
            entry = entry_point(spec.main)
        except (SpareSpecError, ValueError, ImportError) as exc:
            print(f"fork server: no spare apps: {exc}", file=sys.stderr)
            return
        if self.spares is not None:
            self.spares.close()
        self.spares = SparePool(spec, lambda spec, control: _run_spare(entry, spec, control))

    def _reap(self) -> None:
        while True:
            try:
                pid, status = os.waitpid(-1, os.WNOHANG)
            except ChildProcessError:
                return
            if pid == 0:
                return
            if self.spares is not None and self.spares.ended(pid):
                continue  # a spare nobody had taken: the lab server never heard of it
            _send(self.control, {"exit": pid, "code": os.waitstatus_to_exitcode(status)})


def lower_priority(niceness: int, pid: int = 0) -> None:
    """Run process ``pid`` (0: this one), in a session of its own, ``niceness`` steps lower
    than this process runs.

    Where the kernel groups processes by session for scheduling (Linux's autogroup, on by
    default in most distributions), a process in a session of its own is weighed as a group,
    against the server's group, and only the group's nice value tells: the process's own would
    change nothing. Both are set; either may be refused (then it runs as it is).
    """
    with contextlib.suppress(OSError):
        ours = os.getpriority(os.PRIO_PROCESS, 0)
        os.setpriority(os.PRIO_PROCESS, pid, min(19, ours + niceness))
    group = f"/proc/{pid or 'self'}/autogroup"
    if not _set_group_niceness(group, niceness):
        # the kernel takes one such change every 0.1 s from an unprivileged server (a class
        # logging in at once asks for more): it is tried again beside the app
        threading.Thread(target=_retry_group_niceness, args=(group, niceness), daemon=True).start()


#: how long a group's niceness is tried again for, seconds
GROUP_NICENESS_TRIES_S = 60.0


def _set_group_niceness(group: str, niceness: int) -> bool:
    """False when the kernel asks to try again later; True when set or not to be had."""
    try:
        with open(group, "w") as file:
            file.write(str(niceness))
    except BlockingIOError:  # EAGAIN: another process set one within the last 0.1 s
        return False
    except OSError:  # no autogroup here, or not allowed: the process runs as it is
        return True
    return True


def _retry_group_niceness(group: str, niceness: int) -> None:
    deadline = time.monotonic() + GROUP_NICENESS_TRIES_S
    spread = random.Random(os.getpid())  # processes retrying at once do not keep colliding
    while time.monotonic() < deadline:
        time.sleep(0.05 + spread.random() * 0.1)
        if _set_group_niceness(group, niceness):
            return


def limit_memory(cap: int, pid: int = 0) -> None:
    """Let process ``pid`` (0: this one) have at most ``cap`` bytes of memory (0: no cap): past
    it, its allocations fail (Python's MemoryError) and it ends. A cap the system refuses
    leaves it as it is."""
    if cap <= 0:
        return
    with contextlib.suppress(OSError, ValueError):
        _, hard = resource.getrlimit(MEMORY_LIMIT)
        if hard != resource.RLIM_INFINITY:
            cap = min(cap, hard)
        if pid:
            resource.prlimit(pid, MEMORY_LIMIT, (cap, cap))
        else:
            resource.setrlimit(MEMORY_LIMIT, (cap, cap))


def _run_app(
    main: Callable[[object], int],
    settings: dict,
    env: dict[str, str],
    fds: list[int],
    cwd: str | None,
    memory: int = 0,
) -> int:
    """In the forked child: become the session's app."""
    io, errors = fds
    os.dup2(io, 0)
    os.dup2(io, 1)
    os.dup2(errors, 2)
    for fd in fds:
        if fd > 2:
            os.close(fd)
    limit_memory(memory)
    _become_app(env, cwd)
    return main(settings)


def _become_app(env: dict[str, str], cwd: str | None) -> None:
    """In a forked child: an app's priority, signals, environment, folder and argv."""
    signal.signal(signal.SIGINT, signal.default_int_handler)
    lower_priority(APP_NICENESS)
    os.environ.clear()
    os.environ.update(env)
    if cwd:
        with contextlib.suppress(OSError):
            os.chdir(cwd)
    sys.argv = ["workbench"]


def _run_spare(main: Callable[..., int], spec: SpareSpec, control: socket.socket) -> int:
    """In a forked spare: start the app from the template and let it wait for its session
    (:mod:`.spares`). Until then it reads a pipe nobody writes and writes to nothing."""
    idle_r, _open = os.pipe()  # its write end stays open: the input never ends while it waits
    nothing = os.open(os.devnull, os.O_WRONLY)
    os.dup2(idle_r, 0)
    os.dup2(nothing, 1)
    os.close(idle_r)
    os.close(nothing)
    _become_app(spec.env, spec.cwd)
    return main(spec.settings, control)


def serve_main(argv: list[str] | None = None) -> int:
    """The fork server process: preload, report ready, serve; a forked child runs its app."""
    args = sys.argv[1:] if argv is None else argv
    control = socket.socket(fileno=int(args[0]))
    control.setblocking(True)
    signal.signal(signal.SIGINT, signal.SIG_IGN)  # the lab server decides when this ends
    started = time.perf_counter()
    try:
        main = entry_point(args[1])
        modules = preload(tuple(args[2:]))
    except Exception as exc:
        _send(control, {"failed": f"{type(exc).__name__}: {exc}"})
        return 1
    if threading.active_count() > 1:
        _send(control, {"failed": "a thread was started while preloading; forking is unsafe"})
        return 1
    gc.collect()
    gc.freeze()  # the children leave the preloaded objects alone, so their pages stay shared
    _send(control, {"ready": modules, "seconds": round(time.perf_counter() - started, 3)})
    app = _Zygote(control, main).serve()
    if app is None:
        return 0
    return app()


# -- the lab server's side ------------------------------------------------------------------
class ForkedApp:
    """An app forked by the fork server, with the face of ``asyncio.subprocess.Process``."""

    def __init__(
        self,
        pid: int,
        reader: asyncio.StreamReader,
        writer: asyncio.StreamWriter,
        ended: Ended,
    ) -> None:
        self.pid = pid
        self.stdout = reader
        self.stdin = writer
        self._ended = ended

    @property
    def returncode(self) -> int | None:
        ended = self._ended
        if not ended.done() or ended.cancelled():
            return None
        code = ended.result()
        return UNKNOWN_STATUS if code is None else code

    @property
    def status_known(self) -> bool:
        """False for an app that ended after the fork server was lost: its status is a guess."""
        return not self._ended.done() or self._ended.result() is not None

    async def wait(self) -> int:
        code = await asyncio.shield(self._ended)
        return UNKNOWN_STATUS if code is None else code


class ForkServer:
    """Starts the fork server process and asks it for apps."""

    def __init__(
        self,
        env: dict[str, str],
        main: str,
        preload: tuple[str, ...] = (),
        *,
        start_timeout: float = 60.0,
    ) -> None:
        self.env = env
        #: the app's entry point, ``module:function`` taking the app's settings (a JSON object)
        self.main = main
        #: modules the fork server imports before it forks (the app's own)
        self.preload = preload
        self.start_timeout = start_timeout
        self.process: asyncio.subprocess.Process | None = None
        self.modules = 0
        self.seconds = 0.0
        self._sock: socket.socket | None = None
        self._ready: asyncio.Future[dict] | None = None
        self._answers: collections.deque[asyncio.Future[tuple[int, Ended]]] = collections.deque()
        self._ended: dict[int, Ended] = {}
        self._watching: dict[int, int] = {}  # pidfd per child, once the fork server is lost
        self._running = False

    @property
    def running(self) -> bool:
        return self._running

    @property
    def pid(self) -> int | None:
        return self.process.pid if self.process else None

    async def start(self) -> None:
        """Start the process and wait until it has preloaded; ForkServerError if it cannot."""
        loop = asyncio.get_running_loop()
        ours, theirs = socket.socketpair(socket.AF_UNIX, socket.SOCK_SEQPACKET)
        try:
            self.process = await asyncio.create_subprocess_exec(
                sys.executable, "-m", "workbench.door.forkserver", str(theirs.fileno()),
                self.main, *self.preload,
                pass_fds=[theirs.fileno()], stdin=asyncio.subprocess.DEVNULL,
                stdout=asyncio.subprocess.DEVNULL, env=self.env, start_new_session=True,
            )  # fmt: skip
        except OSError as exc:
            ours.close()
            raise ForkServerError(f"cannot start it: {exc}") from exc
        finally:
            theirs.close()
        ours.setblocking(False)
        self._sock = ours
        self._ready = loop.create_future()
        self._running = True
        loop.add_reader(ours.fileno(), self._readable)
        try:
            ready = await asyncio.wait_for(asyncio.shield(self._ready), self.start_timeout)
        except (TimeoutError, ForkServerError) as exc:
            await self.close()
            if isinstance(exc, TimeoutError):
                raise ForkServerError(f"not ready after {self.start_timeout:g} s") from None
            raise
        self.modules = int(ready.get("ready", 0))
        self.seconds = float(ready.get("seconds", 0.0))

    def _readable(self) -> None:
        sock = self._sock
        while sock is not None:
            try:
                message = sock.recv(MAX_MESSAGE)
            except (BlockingIOError, InterruptedError):
                return
            except OSError:
                message = b""
            if not message:
                self._lost("it ended")
                return
            try:
                self._answer(json.loads(message))
            except (ValueError, TypeError, AttributeError) as exc:
                log.error("fork server: unreadable message %r: %s", message[:200], exc)

    def _answer(self, message: dict) -> None:
        loop = asyncio.get_running_loop()
        if "exit" in message:
            ended = self._ended.pop(int(message["exit"]), None)
            if ended is not None and not ended.done():
                ended.set_result(int(message["code"]))
        elif "pid" in message or "error" in message:
            waiter = self._answers.popleft() if self._answers else None
            if "pid" in message:
                pid = int(message["pid"])
                ended = self._ended[pid] = loop.create_future()
                if waiter is not None and not waiter.done():
                    waiter.set_result((pid, ended))
                else:  # nobody waits for it any more (the session went while it started)
                    with contextlib.suppress(ProcessLookupError, PermissionError):
                        os.killpg(pid, signal.SIGKILL)
            elif waiter is not None and not waiter.done():
                waiter.set_exception(ForkServerError(str(message["error"])))
        elif self._ready is not None and not self._ready.done():
            if "ready" in message:
                self._ready.set_result(message)
            else:
                self._ready.set_exception(ForkServerError(str(message.get("failed", message))))

    def _lost(self, why: str) -> None:
        """The fork server is gone: no more apps from it; its running apps are watched."""
        if not self._running:
            return
        self._running = False
        if self._sock is not None:
            with contextlib.suppress(Exception):
                asyncio.get_running_loop().remove_reader(self._sock.fileno())
            self._sock.close()
            self._sock = None
        error = ForkServerError(f"the fork server is gone ({why})")
        if self._ready is not None and not self._ready.done():
            self._ready.set_exception(error)
        while self._answers:
            waiter = self._answers.popleft()
            if not waiter.done():
                waiter.set_exception(error)
        if self._ended:
            log.error(
                "fork server gone (%s) with %d apps running; their exit status is not known",
                why,
                len(self._ended),
            )
        for pid in list(self._ended):
            self._watch(pid)

    def _watch(self, pid: int) -> None:
        """Learn the end of an app whose parent is gone, from a pidfd."""
        loop = asyncio.get_running_loop()
        ended = self._ended[pid]

        def gone() -> None:
            fd = self._watching.pop(pid, None)
            if fd is not None:
                loop.remove_reader(fd)
                os.close(fd)
            self._ended.pop(pid, None)
            if not ended.done():
                ended.set_result(None)

        try:
            fd = os.pidfd_open(pid)
        except OSError:  # already gone
            gone()
            return
        self._watching[pid] = fd
        loop.add_reader(fd, gone)

    def keep_spares(
        self,
        count: int,
        main: str,
        settings: dict,
        env: dict[str, str],
        personal: frozenset[str],
        cwd: str | None = None,
    ) -> None:
        """Have the fork server keep ``count`` spare apps (:mod:`.spares`): started ahead with
        the entry point ``main`` from ``settings`` and ``env``, each handed to a session whose
        own differ from them only in ``personal`` settings (and the terminal's size)."""
        if not self._running or self._sock is None:
            raise ForkServerError("the fork server is not running")
        spec = {"count": count, "main": main, "settings": settings, "env": env,
                "personal": sorted(personal), "cwd": cwd or os.getcwd()}  # fmt: skip
        try:
            self._sock.send(json.dumps({"spares": spec}).encode())
        except OSError as exc:
            raise ForkServerError(f"the spares request was not sent: {exc}") from exc

    async def spawn(
        self,
        settings: dict,
        env: dict[str, str],
        errors: Path | int,
        cwd: str | None = None,
        memory: int = 0,
    ) -> ForkedApp:
        """A new app with these settings (a JSON object) and environment, its error output
        written to the descriptor ``errors`` (a pipe's end, say) or appended to the file of
        that path, under a cap of ``memory`` bytes (0: none)."""
        if not self._running or self._sock is None:
            raise ForkServerError("the fork server is not running")
        loop = asyncio.get_running_loop()
        fields = {"settings": settings, "env": env, "cwd": cwd or os.getcwd(), "memory": memory}
        request = json.dumps(fields).encode()
        ours, theirs = socket.socketpair(socket.AF_UNIX, socket.SOCK_STREAM)
        try:
            with contextlib.ExitStack() as opened:
                if not isinstance(errors, int):
                    errors = opened.enter_context(open(errors, "ab")).fileno()
                socket.send_fds(self._sock, [request], [theirs.fileno(), errors])
        except OSError as exc:
            ours.close()
            raise ForkServerError(f"the request was not sent: {exc}") from exc
        finally:
            theirs.close()
        answer: asyncio.Future[tuple[int, Ended]] = loop.create_future()
        self._answers.append(answer)
        try:
            pid, ended = await answer
        except BaseException:
            ours.close()
            raise
        reader, writer = await asyncio.open_unix_connection(sock=ours)
        return ForkedApp(pid, reader, writer, ended)

    async def close(self, timeout: float = 5.0) -> None:
        """Stop the fork server (apps already running are not touched)."""
        self._lost("closed")
        process = self.process
        if process is None or process.returncode is not None:
            return
        try:
            await asyncio.wait_for(process.wait(), timeout)
        except TimeoutError:
            with contextlib.suppress(ProcessLookupError):
                process.kill()
            await process.wait()


if __name__ == "__main__":
    raise SystemExit(serve_main())
