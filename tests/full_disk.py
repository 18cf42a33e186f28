"""A disk that fills up on demand, for the run-record writer: its writes fail with ENOSPC (as a
full disk's do) while ``full`` is set, and work again once it is cleared."""

from __future__ import annotations

import builtins
import errno
import os
from typing import Any


class FullableFile:
    """A real file whose writes fail with ENOSPC while its disk is full."""

    def __init__(self, disk: FakeDisk, real: Any) -> None:
        self._disk = disk
        self._real = real

    def write(self, data: bytes) -> int:
        if self._disk.full:
            self._disk.refused += 1
            raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))
        return self._real.write(data)

    def __getattr__(self, name: str) -> Any:
        return getattr(self._real, name)


class FakeDisk:
    def __init__(self) -> None:
        self.full = False
        self.refused = 0

    def open(self, path: Any, mode: str = "r", *args: Any, **kwargs: Any) -> Any:
        real = builtins.open(path, mode, *args, **kwargs)  # noqa: SIM115
        return FullableFile(self, real) if "w" in mode or "a" in mode else real
