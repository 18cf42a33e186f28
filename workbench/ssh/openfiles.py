"""The lab server's open files: its limit raised as far as it may go, and new connections
refused (not left to fail) while few descriptors are left.

Every connection holds a socket and every session a few more descriptors (its app's socket or
pipes); at the process's limit ``accept`` fails, and asyncio would log the error with its
traceback on every try, once a second, while the waiting connections time out. So the server
refuses a connection whose socket is among the last :data:`RESERVE` descriptors, keeping those
for the sessions already in, and says so in one line now and then; and an ``accept`` that fails
all the same is logged the same way, without a traceback.
"""

from __future__ import annotations

import asyncio
import errno
import os
import resource
from collections.abc import Callable
from typing import Any

#: descriptors kept for the sessions already in (their apps' sockets, pipes and logs)
RESERVE = 64
#: the errors of an ``accept`` that ran out of descriptors or memory
OUT_OF_FILES = frozenset({errno.EMFILE, errno.ENFILE, errno.ENOBUFS, errno.ENOMEM})


def raise_file_limit() -> tuple[int, int]:
    """Raise this process's soft limit on open files to its hard limit, where allowed;
    ``(before, after)``."""
    soft, hard = resource.getrlimit(resource.RLIMIT_NOFILE)
    if hard == resource.RLIM_INFINITY or soft == hard:
        return soft, soft
    try:
        resource.setrlimit(resource.RLIMIT_NOFILE, (hard, hard))
    except (ValueError, OSError):
        return soft, soft
    return soft, hard


def file_limit() -> int:
    return resource.getrlimit(resource.RLIMIT_NOFILE)[0]


def near_the_limit(fd: int, limit: int) -> bool:
    """Whether descriptor ``fd``, just made, is among the last :data:`RESERVE` below ``limit``.

    A new descriptor takes the lowest number free (POSIX), so ``fd`` counts the descriptors
    open below it: no need to list them."""
    if limit == resource.RLIM_INFINITY or limit <= 0:
        return False
    return fd >= max(limit - RESERVE, limit // 2)


def room_for_a_file(limit: int) -> bool:
    """Whether a file opened now would stay out of the last :data:`RESERVE` descriptors (a
    probe is opened and closed at once: it takes the number the file would)."""
    try:
        fd = os.open(os.devnull, os.O_RDONLY)
    except OSError:
        return False
    os.close(fd)
    return not near_the_limit(fd, limit)


Say = Callable[[str, str], None]


Handler = Callable[[asyncio.AbstractEventLoop, dict[str, Any]], object] | None


def quiet_accept_errors(loop: asyncio.AbstractEventLoop, say: Say) -> Handler:
    """Have ``loop`` report an ``accept`` that ran out of descriptors, and anything that ran
    out of memory, with ``say(key, message)`` (which keeps repeats out of the log) instead of
    a traceback; other errors go on to the handler there was, which is returned (to be put
    back)."""
    previous = loop.get_exception_handler()

    def handle(loop: asyncio.AbstractEventLoop, context: dict[str, Any]) -> None:
        exc = context.get("exception")
        if isinstance(exc, OSError) and exc.errno in OUT_OF_FILES:
            say(
                "out of files",
                f"new connections wait: the server cannot take them ({exc.strerror}, "
                f"limit {file_limit()} open files)",
            )
            return
        if isinstance(exc, MemoryError):
            what = str(context.get("message", "a task"))[:80]
            say("out of memory", f"out of memory ({what}): that work was dropped")
            return
        if previous is not None:
            previous(loop, context)
        else:
            loop.default_exception_handler(context)

    loop.set_exception_handler(handle)
    return previous
