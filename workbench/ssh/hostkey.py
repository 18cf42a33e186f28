"""The server's Ed25519 host key: made on first start, kept readable by its owner only.

Students' SSH clients remember the key on first connection; keeping it (and backing it up)
avoids the "REMOTE HOST IDENTIFICATION HAS CHANGED" warning after a reinstall.
"""

from __future__ import annotations

import logging
import os
import stat
from pathlib import Path

import asyncssh

HOST_KEY_FILE = "ssh_host_ed25519_key"

log = logging.getLogger("workbench.ssh")


class HostKeyError(Exception):
    """The host key file exists but cannot be used; the message names it."""


def host_key_path(data_dir: str | os.PathLike) -> Path:
    return Path(data_dir) / HOST_KEY_FILE


def load_or_create_host_key(path: str | os.PathLike) -> asyncssh.SSHKey:
    """The private host key at ``path``, generated (mode 0600) when the file does not exist."""
    path = Path(path)
    try:
        key = asyncssh.read_private_key(path)
    except FileNotFoundError:
        return _create(path)
    except (asyncssh.KeyImportError, OSError) as exc:
        raise HostKeyError(
            f"{path}: not a usable SSH private key ({exc}); move it away to make a new one"
        ) from None
    mode = stat.S_IMODE(path.stat().st_mode)
    if mode & 0o077:
        os.chmod(path, 0o600)
        log.warning("host key %s was readable by others (mode %o): now 0600", path, mode)
    return key


def _create(path: Path) -> asyncssh.SSHKey:
    path.parent.mkdir(parents=True, exist_ok=True)
    key = asyncssh.generate_private_key("ssh-ed25519", comment="workbench lab server")
    fd = os.open(path, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o600)
    with os.fdopen(fd, "wb") as out:
        out.write(key.export_private_key("openssh"))
    public = path.with_name(path.name + ".pub")
    public.write_bytes(key.export_public_key("openssh"))
    log.info("made a new host key %s (%s)", path, key.get_fingerprint())
    return key
