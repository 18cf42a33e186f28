"""Writing a file whole: a crash or a full disk leaves either the old file or the new one.

The new content goes to a temporary file beside the target, is flushed to the disk, and then
takes the target's place in one step (``os.replace``). The one way every file the workbench
writes in place is saved: mazes, rosters, gradebooks, the SSH users file, the last pair and
the pending store writes. Once in place, the file is announced (:func:`.commits.committed`).
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
