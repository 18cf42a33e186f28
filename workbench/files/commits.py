"""Telling whoever listens that a file is complete on disk.

The atomic writer (:mod:`.atomic`) calls :func:`committed` once a file has taken its place,
and a run record calls it once the record is closed. A listener (the workspace's copy in the
course store, :mod:`workbench.labs.store.workspace_sync`) must return at once: it only notes the
path, and does its own work elsewhere. A listener that fails is logged and never fails the
write that was already done.
"""

from __future__ import annotations

import logging
import os
import threading
from collections.abc import Callable
from pathlib import Path

log = logging.getLogger(__name__)

Listener = Callable[[Path], None]

_listeners: list[Listener] = []
_lock = threading.Lock()


def on_commit(listener: Listener) -> None:
    """Call ``listener(path)`` after every file this process completes."""
    with _lock:
        _listeners.append(listener)


def forget(listener: Listener) -> None:
    """Stop calling ``listener`` (no error when it was not listening)."""
    with _lock:
        if listener in _listeners:
            _listeners.remove(listener)


def committed(path: str | os.PathLike) -> None:
    """Tell every listener that ``path`` is complete on disk."""
    with _lock:
        listeners = list(_listeners)
    for listener in listeners:
        try:
            listener(Path(path))
        except Exception:  # the file is written; a listener's trouble is its own
            log.exception("a listener failed on the file %s", path)
