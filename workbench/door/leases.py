"""The workbench sessions of every door serving one data folder, counted per user: the
per-user cap (``--max-per-user``) holds over SSH and the browser together.

Each open session holds a **lease**: a file ``<data-dir>/sessions/<user>/<door>-<pid>-<n>``
locked with ``flock`` by the server process that opened the session, for as long as the session
lasts. A lease is counted while its lock is held; the kernel lets go of the lock when that
process ends in any way (a stop, a crash, ``kill -9``, the out-of-memory killer), so a crashed
server leaves no session counted: the next count finds its file unlocked and removes it. Nothing
expires on a clock and no server has to be alive to clean up after another, which a table in
the course store (rows outliving a killed server until a heartbeat runs out, and a cap that
waits on a database that may be down) would need.

A count and the new lease it allows are made under the user's folder lock (``.lock``, held for
a few system calls), so two doors starting sessions for one student at once cannot both pass
the cap. A server counts its own leases from memory and never opens their files again: where
``flock`` is done with POSIX locks (NFS), a process's own locks do not conflict with it and
closing another descriptor of the file would drop them.

The data folder is per machine: servers on several machines behind a balancer each count the
sessions of their own data folder.
"""

from __future__ import annotations

import contextlib
import errno
import fcntl
import itertools
import json
import os
import threading
import time
from dataclasses import dataclass, field
from pathlib import Path

FOLDER = "sessions"
LOCK = ".lock"


@dataclass
class Lease:
    """One open session's lease; :meth:`release` when the session ends."""

    user: str
    path: Path
    _fd: int | None = field(repr=False)
    _owner: SessionLeases = field(repr=False)

    def release(self) -> None:
        self._owner._release(self)


class SessionLeases:
    """This server's leases in ``data_dir``, and the count of everyone's (see the module)."""

    def __init__(self, data_dir: Path, door: str) -> None:
        self.folder = Path(data_dir) / FOLDER
        self.door = door
        self._own: dict[str, set[str]] = {}
        self._numbers = itertools.count(1)
        self._lock = threading.Lock()

    def count(self, user: str) -> int:
        """The user's sessions open now, by every server of the data folder."""
        folder = self._user_folder(user)
        with self._lock, _locked(folder):
            return self._count(user, folder)

    def take(self, user: str, most: int, what: str = "") -> tuple[Lease | None, int]:
        """A lease for one more session of ``user``, unless they hold ``most`` already: the
        lease (None when refused) and how many they held before it."""
        folder = self._user_folder(user)
        with self._lock, _locked(folder):
            held = self._count(user, folder)
            if held >= most:
                return None, held
            name = f"{self.door}-{os.getpid()}-{next(self._numbers)}"
            path = folder / name
            fd = os.open(path, os.O_RDWR | os.O_CREAT | os.O_EXCL | os.O_CLOEXEC, 0o600)
            try:
                fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
                said = {"door": self.door, "pid": os.getpid(), "since": time.time(), "what": what}
                os.write(fd, (json.dumps(said) + "\n").encode())
            except BaseException:
                os.close(fd)
                with contextlib.suppress(OSError):
                    path.unlink()
                raise
            self._own.setdefault(user, set()).add(name)
            return Lease(user, path, fd, self), held

    def _release(self, lease: Lease) -> None:
        with self._lock:
            fd, lease._fd = lease._fd, None
            if fd is None:
                return
            names = self._own.get(lease.user, set())
            names.discard(lease.path.name)
            if not names:
                self._own.pop(lease.user, None)
            with contextlib.suppress(OSError):
                lease.path.unlink()  # before the lock goes: no one counts it gone and removes it
            os.close(fd)

    def _user_folder(self, user: str) -> Path:
        if "/" in user or user in ("", ".", "..") or user.startswith("."):
            raise ValueError(f"{user!r} cannot name a sessions folder")
        folder = self.folder / user
        folder.mkdir(mode=0o700, parents=True, exist_ok=True)
        return folder

    def _count(self, user: str, folder: Path) -> int:
        own = self._own.get(user, set())
        held = len(own)
        for entry in os.scandir(folder):
            if entry.name.startswith(".") or entry.name in own:
                continue
            if _held(Path(entry.path)):
                held += 1
        return held


@contextlib.contextmanager
def _locked(folder: Path):
    fd = os.open(folder / LOCK, os.O_RDWR | os.O_CREAT | os.O_CLOEXEC, 0o600)
    try:
        fcntl.flock(fd, fcntl.LOCK_EX)
        yield
    finally:
        os.close(fd)


def _held(path: Path) -> bool:
    """Whether another process holds the lease ``path``; one no one holds is removed (its
    server ended without releasing it)."""
    try:
        fd = os.open(path, os.O_RDWR | os.O_CLOEXEC)
    except FileNotFoundError:
        return False
    try:
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError as exc:
            if exc.errno in (errno.EWOULDBLOCK, errno.EAGAIN):
                return True
            raise
        with contextlib.suppress(OSError):
            path.unlink()
        return False
    finally:
        os.close(fd)
