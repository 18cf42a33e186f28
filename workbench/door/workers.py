"""The server's worker threads, one pool per kind of work, so one kind stuck cannot hold up
another: the course store (a session's start waits on it, and a locked table can hold a call
for as long as the lock), password checks (a login waits on them), and SFTP's file work (a
listing or a read of a big folder or file, kept off the event loop that serves every student).

asyncio's default pool has ``min(32, CPUs + 4)`` threads, six on a 2-core machine: sixteen
session starts waiting on a locked store table took every one of them, and the logins behind
them waited for a thread to check their passwords.
"""

from __future__ import annotations

import asyncio
import functools
from collections.abc import Callable
from concurrent.futures import ThreadPoolExecutor
from typing import ParamSpec, TypeVar

P = ParamSpec("P")
T = TypeVar("T")

#: calls to the course store (a session start's workspace sync, uploads sent on)
STORE = ThreadPoolExecutor(max_workers=64, thread_name_prefix="ssh-store")
#: password checks
PASSWORDS = ThreadPoolExecutor(max_workers=4, thread_name_prefix="ssh-passwords")
#: SFTP listings, reads and upload flushes
FILES = ThreadPoolExecutor(max_workers=8, thread_name_prefix="ssh-files")


async def in_pool(
    pool: ThreadPoolExecutor, call: Callable[P, T], *args: P.args, **kwargs: P.kwargs
) -> T:
    """``call(*args, **kwargs)`` in a thread of ``pool``, awaited."""
    loop = asyncio.get_running_loop()
    return await loop.run_in_executor(pool, functools.partial(call, *args, **kwargs))
