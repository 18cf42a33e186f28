"""Spare apps: session apps the fork server starts before their students come.

A Textual app's start to its first screen costs some 80 ms of CPU however little it shows, so
a class that logs in at once waits for thirty of them to share the machine's cores. With
``--spare-apps N`` the lab server asks its fork server (:mod:`.forkserver`) to keep N apps
started ahead from the session settings every student shares (the *template*): each runs to
the names dialog with no terminal (its output goes nowhere, no key can reach it) and waits.
A session whose settings and environment differ from the template only in what is the
session's own (the student, their ports, workspace and record folder: the app names them, see
``SESSION_FIELDS`` in ``workbench/wire/settings.py``; the terminal's size) is handed a waiting
spare instead of a new fork: the spare gets the session's socket, error output, settings,
environment and folder in one message on its own control socket (the app's side is
``workbench/tui/serving/seat.py``), takes them and draws its whole screen for the student's
terminal. Any other session (an instructor's console, another terminal type, a setting of its
own) is forked as before, and so is every session once the spares are used up.

The pool is filled again once no student has come for :data:`REFILL_QUIET` seconds, so the
spares' own starts do not compete with a class arriving. A spare that ends before a student
takes it is replaced, after a pause that doubles while spares keep ending (up to
:data:`MAX_BACKOFF`), so a template that cannot start is not started in a loop.
"""

from __future__ import annotations

import collections
import contextlib
import json
import os
import signal
import socket
import sys
import time
from collections.abc import Callable
from dataclasses import dataclass

#: the terminal's size: the session's own in the environment (and ``TERM``, as far as
#: :func:`term_colours` says it draws alike)
SESSION_ENV = frozenset({"COLUMNS", "ROWS"})
#: seconds without a new session before spares are started again
REFILL_QUIET = 1.0
#: the longest pause before replacing spares that ended on their own
MAX_BACKOFF = 60.0
#: the most spares a pool keeps
MAX_SPARES = 500
_ABSENT = object()


class SpareSpecError(ValueError):
    """A spares request that cannot be kept."""


@dataclass(frozen=True)
class SpareSpec:
    """What the spares are started with, and which sessions may have one."""

    count: int
    #: the spare's entry point, ``module:function`` taking the template settings and the
    #: spare's control socket
    main: str
    #: the template: settings every session shares (a JSON object)
    settings: dict
    env: dict[str, str]
    #: the settings that are each session's own (a spare takes the session's)
    personal: frozenset[str]
    cwd: str | None = None

    @classmethod
    def from_message(cls, message: object) -> SpareSpec:
        """The spec in a ``{"spares": ...}`` request; SpareSpecError says what is wrong."""
        if not isinstance(message, dict):
            raise SpareSpecError("the spares request is not a JSON object")
        try:
            count = int(message["count"])
            main = str(message["main"])
            settings = message["settings"]
            env = {str(k): str(v) for k, v in message["env"].items()}
            personal = frozenset(str(name) for name in message.get("personal", ()))
            cwd = message.get("cwd")
        except (KeyError, TypeError, ValueError, AttributeError) as exc:
            raise SpareSpecError(f"bad spares request: {exc!r}") from None
        if not 0 <= count <= MAX_SPARES:
            raise SpareSpecError(f"{count} spares: between 0 and {MAX_SPARES}")
        if not isinstance(settings, dict):
            raise SpareSpecError("the spares' settings are not a JSON object")
        return cls(count, main, settings, env, personal, str(cwd) if cwd else None)

    def fits(self, settings: dict, env: dict[str, str]) -> bool:
        """Whether a session with these settings and environment may have a spare: they
        differ from the template's only in what is the session's own."""
        for name in (settings.keys() | self.settings.keys()) - self.personal:
            if settings.get(name, _ABSENT) != self.settings.get(name, _ABSENT):
                return False
        return _shared(env) == _shared(self.env)


def _shared(env: dict[str, str]) -> dict[str, str]:
    shared = {k: v for k, v in env.items() if k not in SESSION_ENV}
    if "TERM" in shared:
        shared["TERM"] = term_colours(shared["TERM"])
    return shared


def term_colours(term: str) -> str:
    """What a terminal type changes in an app: the colours it draws in, which Rich (under
    Textual) takes from the end of ``TERM`` (``xterm-256color``, ``screen-256color`` and
    ``tmux-256color`` all draw in 256 colours; ``xterm`` in 16; ``dumb`` in none). Sessions
    whose terminals draw alike may have the same spare; each gets its own ``TERM``."""
    term = term.strip().lower()
    if term in ("dumb", "unknown"):
        return "none"
    return "256" if term.rpartition("-")[2] in ("256color", "kitty") else "16"


@dataclass
class Spare:
    pid: int
    #: the fork server's end of the spare's control socket
    control: socket.socket


class SparePool:
    """The fork server's spares: started, handed out, replaced."""

    def __init__(
        self,
        spec: SpareSpec,
        run: Callable[[SpareSpec, socket.socket], int],
        *,
        clock: Callable[[], float] = time.monotonic,
    ) -> None:
        """``run(spec, control)`` is what a spare's process does (in the forked child)."""
        self.spec = spec
        self._run = run
        self._clock = clock
        self.waiting: collections.deque[Spare] = collections.deque()
        self._refill_at: float | None = clock()
        self._backoff = REFILL_QUIET

    # -- filling ---------------------------------------------------------------------------
    def wait_time(self) -> float | None:
        """Seconds until spares are started again (None: the pool is full)."""
        if self._refill_at is None:
            return None
        return max(0.0, self._refill_at - self._clock())

    def refill(self) -> Callable[[], int] | None:
        """Start spares until there are :attr:`SpareSpec.count`, when it is time; in a forked
        child, the function that runs it."""
        if self._refill_at is None or self._clock() < self._refill_at:
            return None
        self._refill_at = None
        while len(self.waiting) < self.spec.count:
            ours, theirs = socket.socketpair(socket.AF_UNIX, socket.SOCK_SEQPACKET)
            try:
                pid = os.fork()
            except OSError as exc:
                ours.close()
                theirs.close()
                print(f"fork server: no spare app started: {exc}", file=sys.stderr)
                self._later(self._backoff)
                return None
            if pid == 0:
                os.setsid()
                ours.close()
                for spare in self.waiting:  # the other spares' ends are the fork server's
                    spare.control.close()
                self.waiting.clear()
                return lambda: self._run(self.spec, theirs)
            theirs.close()
            self.waiting.append(Spare(pid, ours))
        return None

    def _later(self, seconds: float) -> None:
        at = self._clock() + seconds
        self._refill_at = at if self._refill_at is None else min(self._refill_at, at)

    # -- handing out -----------------------------------------------------------------------
    def take(self, request: dict, fds: list[int], limit: Callable[[int, int], None]) -> int | None:
        """Hand a session's request (``settings``, ``env``, ``cwd``, ``memory``) and its two
        descriptors to a waiting spare; its pid, or None when none may have it (the caller
        forks a new app). ``limit(memory, pid)`` puts the session's memory cap on the spare."""
        settings, env = request.get("settings"), request.get("env")
        if not self.waiting or not isinstance(settings, dict) or not isinstance(env, dict):
            return None
        if not self.spec.fits(settings, env):
            return None
        message = json.dumps({"settings": settings, "env": env, "cwd": request.get("cwd")}).encode()
        while self.waiting:
            spare = self.waiting.popleft()
            try:
                limit(int(request.get("memory", 0)), spare.pid)
                socket.send_fds(spare.control, [message], fds)
            except OSError:  # it ended meanwhile: the next one
                with contextlib.suppress(OSError):
                    os.killpg(spare.pid, signal.SIGKILL)
                spare.control.close()
                continue
            spare.control.close()  # nothing more goes to it: the session has it now
            self._backoff = REFILL_QUIET
            self._refill_at = self._clock() + REFILL_QUIET  # once the arrivals pause
            return spare.pid
        return None

    def ended(self, pid: int) -> bool:
        """A child ended: whether it was a waiting spare (replaced after a pause; nobody else
        knew it)."""
        for spare in self.waiting:
            if spare.pid == pid:
                self.waiting.remove(spare)
                spare.control.close()
                print(
                    f"fork server: a spare app ended before its student came (pid {pid}); "
                    f"another in {self._backoff:g} s",
                    file=sys.stderr,
                )
                self._later(self._backoff)
                self._backoff = min(MAX_BACKOFF, self._backoff * 2)
                return True
        return False

    def close(self) -> None:
        """No more spares: each waiting one sees its control socket close and ends."""
        self._refill_at = None
        while self.waiting:
            self.waiting.popleft().control.close()
