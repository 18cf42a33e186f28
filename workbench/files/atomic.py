"""Writing a file whole: a crash or a full disk leaves either the old file or the new one.

The new content goes to a temporary file beside the target (for a file written piece by
piece, :class:`PendingFile`, in a hidden folder on the same file system), is flushed to the
disk, and then takes the target's place in one step (``os.replace``). The one way every file
the workbench writes in place is saved: mazes, rosters, gradebooks, the SSH users file, the
last pair, the pending store writes and the files students upload to the lab server.
Once in place, the file is announced (:func:`.commits.committed`).
"""

from __future__ import annotations

import contextlib
import os
import tempfile
from pathlib import Path

from .commits import committed


def write_text_atomic(path: str | os.PathLike, text: str, mode: int | None = None) -> None:
    """Write ``text`` as UTF-8 (see :func:`write_bytes_atomic`)."""
    write_bytes_atomic(path, text.encode("utf-8"), mode)


def write_bytes_atomic(path: str | os.PathLike, data: bytes, mode: int | None = None) -> None:
    """Write ``data`` to ``path`` whole. The file gets ``mode`` when given (``0o600`` for one
    that holds secrets); otherwise it keeps the permissions it had, and a new file gets the
    usual ones the umask allows. The folder must exist."""
    target = Path(path)
    fd, temp = tempfile.mkstemp(prefix=f".{target.name}.", suffix=".tmp", dir=target.parent)
    try:
        os.fchmod(fd, _mode_for(target) if mode is None else mode)
        with os.fdopen(fd, "wb") as fh:
            fh.write(data)
            fh.flush()
            os.fsync(fh.fileno())
        os.replace(temp, target)
    except BaseException:
        with contextlib.suppress(OSError):
            os.unlink(temp)
        raise
    committed(target)


def _mode_for(path: Path) -> int:
    """An existing file's permissions; for a new file, the usual ones the umask allows."""
    try:
        return path.stat().st_mode & 0o7777
    except OSError:
        umask = os.umask(0)
        os.umask(umask)
        return 0o666 & ~umask


class PendingFile:
    """A file written piece by piece that appears whole or not at all: the pieces go to a
    temporary file in ``folder`` (a hidden one, on the same file system as the target), and
    :meth:`commit` flushes it to the disk and puts it in the target's place in one step.
    :meth:`discard` removes it; nothing of it is ever seen under the target's name."""

    def __init__(self, folder: Path, stem: str = "pending", mode: int = 0o600) -> None:
        fd, temp = tempfile.mkstemp(prefix=f".{stem}.", suffix=".tmp", dir=folder)
        os.fchmod(fd, mode)
        self.fd: int | None = fd
        self.temp = Path(temp)

    @property
    def open(self) -> bool:
        return self.fd is not None

    def write(self, offset: int, data: bytes) -> None:
        assert self.fd is not None
        view = memoryview(data)
        while view:
            done = os.pwrite(self.fd, view, offset)
            view, offset = view[done:], offset + done

    def read(self, offset: int, size: int) -> bytes:
        assert self.fd is not None
        return os.pread(self.fd, size, offset)

    def truncate(self, size: int) -> None:
        assert self.fd is not None
        os.ftruncate(self.fd, size)

    def size(self) -> int:
        assert self.fd is not None
        return os.fstat(self.fd).st_size

    def commit(self, target: str | os.PathLike) -> None:
        """Flush the file and put it at ``target``, replacing what is there."""
        assert self.fd is not None
        try:
            os.fsync(self.fd)
        finally:
            os.close(self.fd)
            self.fd = None
        try:
            os.replace(self.temp, target)
        except BaseException:
            self.discard()
            raise

    def discard(self) -> None:
        if self.fd is not None:
            os.close(self.fd)
            self.fd = None
        with contextlib.suppress(OSError):
            os.unlink(self.temp)
