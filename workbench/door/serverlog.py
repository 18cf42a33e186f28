"""The lab server's log: ``<data-dir>/ssh.log`` (and standard error), kept to a size (a full
log is kept once as ``ssh.log.1`` and a new one begun), and how names a client chose are shown
in it."""

from __future__ import annotations

import logging
import logging.handlers
import os
import sys
from pathlib import Path

from workbench.files.private import private_dir, tighten_tree

log = logging.getLogger("workbench.ssh")

#: bytes ``ssh.log`` grows to before it is kept as ``ssh.log.1`` (so twice this on disk)
SERVER_LOG_SIZE = 20_000_000


def shown(name: str) -> str:
    """A login name as the log shows it: at most 64 characters, no control characters."""
    return "".join(c if c.isprintable() else "?" for c in name[:64])


def setup_logging(
    data_dir: Path,
    stream: bool = True,
    size: int = SERVER_LOG_SIZE,
    *,
    file_name: str = "ssh.log",
    also: tuple[str, ...] = (),
) -> Path:
    """Log the server's events to ``<data-dir>/ssh.log`` (the browser door's to
    ``web.log``, with its own logger among ``also``) and stderr, the log kept within ``size``
    bytes and one older log (0: no limit); returns the log's path.
    The data folder and everything in it are made private to the server's account first, and
    so is all the server and its apps make from now on (a umask of 077): they hold students'
    progress and login addresses."""
    os.umask(0o077)
    changed = [n for n in (private_dir(data_dir), *tighten_tree(data_dir)) if n]
    path = data_dir / file_name
    formatter = logging.Formatter("%(asctime)s %(levelname)s %(message)s")
    handlers: list[logging.Handler] = [
        logging.handlers.RotatingFileHandler(
            path, maxBytes=size, backupCount=1 if size else 0, encoding="utf-8"
        )
    ]
    if stream:
        handlers.append(logging.StreamHandler(sys.stderr))
    loggers = [log, *(logging.getLogger(name) for name in also)]
    for handler in handlers:
        handler.setFormatter(formatter)
        for logger in loggers:
            logger.addHandler(handler)
    for logger in loggers:
        logger.setLevel(logging.INFO)
    logging.getLogger("asyncssh").setLevel(logging.WARNING)
    if changed:
        log.warning(
            "made private to this account: %d file(s) and folder(s) of %s were open to other "
            "accounts, e.g. %s",
            len(changed),
            data_dir,
            changed[0],
        )
    return path
