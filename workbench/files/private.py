"""Files and folders only their owner may read: the data folder and what the workbench makes
in it (the database, pending writes, the lab server's logs) hold students' progress and login
addresses. Folders are made ``0700`` and files ``0600`` whatever the umask, and one found open
to others is tightened, with a notice saying what was changed.
"""

from __future__ import annotations

import os
import stat
from pathlib import Path

PRIVATE_DIR = 0o700
PRIVATE_FILE = 0o600
#: the most entries :func:`tighten_tree` looks at (a folder of many years' session logs)
MAX_TREE_ENTRIES = 100_000


def private_dir(path: Path) -> str:
    """Make the folder ``path`` (and missing parents) if needed, and leave it private to its
    owner. Returns a notice when an existing folder was open to others, else ``""``. OSError
    if it cannot be made."""
    path.mkdir(parents=True, exist_ok=True, mode=PRIVATE_DIR)
    return tighten(path)


def tighten(path: Path) -> str:
    """Take away the group's and others' access to ``path`` (a folder or a file; a symbolic
    link is left alone). Returns a notice naming what changed, or ``""``."""
    try:
        info = path.lstat()
    except FileNotFoundError:
        return ""
    if stat.S_ISLNK(info.st_mode) or not info.st_mode & 0o077:
        return ""
    if info.st_uid != os.geteuid():
        return ""  # not ours to change (and chmod would fail)
    old = stat.S_IMODE(info.st_mode)
    new = PRIVATE_DIR if stat.S_ISDIR(info.st_mode) else old & 0o700
    os.chmod(path, new)
    return f"{path}: was open to other accounts (mode {old:04o}); made private ({new:04o})"


def tighten_tree(root: Path) -> list[str]:
    """:func:`tighten` ``root`` and everything in it (symbolic links not followed; at most
    :data:`MAX_TREE_ENTRIES` entries). Returns the notices."""
    notices = [tighten(root)]
    seen = 0
    for folder, dirs, files in os.walk(root):
        for name in dirs + files:
            seen += 1
            if seen > MAX_TREE_ENTRIES:
                return [n for n in notices if n]
            try:
                notices.append(tighten(Path(folder) / name))
            except OSError:
                continue  # gone meanwhile, or not changeable: the rest still are
    return [n for n in notices if n]
