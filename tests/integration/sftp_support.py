"""What the SFTP tests share: OpenSSH's ``sftp`` and ``scp`` run against a lab server on
loopback with an account's key, and asyncssh's SFTP client for what OpenSSH cannot send."""

from __future__ import annotations

import asyncio
import shutil
import subprocess
from dataclasses import dataclass
from pathlib import Path

import pytest

from .ssh_support import LabHost

needs_openssh = pytest.mark.skipif(
    shutil.which("sftp") is None or shutil.which("scp") is None,
    reason="no OpenSSH sftp and scp clients (Debian package openssh-client)",
)


@dataclass
class OpenSSH:
    """OpenSSH's clients as one account of ``host``, with its key in ``folder``."""

    host: LabHost
    folder: Path

    def key(self, name: str) -> Path:
        path = self.folder / f"id_{name}"
        if not path.exists():
            key = self.host.accounts[name].key
            assert key is not None
            path.write_bytes(key.export_private_key())
            path.chmod(0o600)
        return path

    def options(self, name: str) -> list[str]:
        return [
            "-F", "/dev/null", "-i", str(self.key(name)), "-P", str(self.host.port),
            "-o", "StrictHostKeyChecking=no", "-o", "UserKnownHostsFile=/dev/null",
            "-o", "BatchMode=yes", "-o", "LogLevel=ERROR",
        ]  # fmt: skip

    async def sftp(self, name: str, *lines: str, timeout: float = 120) -> Done:
        """Run ``sftp -b`` with ``lines`` (a line starting with ``-`` may fail and the batch
        goes on)."""
        batch = self.folder / f"batch-{name}"
        batch.write_text("\n".join(lines) + "\n")
        argv = ["sftp", *self.options(name), "-b", str(batch), f"{name}@127.0.0.1"]
        return await _run(argv, timeout)

    async def scp(self, name: str, *args: str, timeout: float = 60) -> Done:
        """``scp ARGS`` where ``@:`` in an argument stands for ``NAME@127.0.0.1:``."""
        argv = ["scp", *self.options(name)]
        argv += [a.replace("@:", f"{name}@127.0.0.1:") for a in args]
        return await _run(argv, timeout)


@dataclass
class Done:
    status: int
    stdout: str
    stderr: str

    @property
    def said(self) -> str:
        """What the client printed, its lines joined (a long line may be cut by a terminal)."""
        return " ".join((self.stdout + "\n" + self.stderr).split())


async def _run(argv: list[str], timeout: float) -> Done:
    done = await asyncio.to_thread(
        subprocess.run, argv, capture_output=True, text=True, timeout=timeout
    )
    return Done(done.returncode, done.stdout, done.stderr)


def files_under(folder: Path) -> dict[str, bytes]:
    """Every file under ``folder`` (its path relative to it) and its bytes."""
    return {
        p.relative_to(folder).as_posix(): p.read_bytes()
        for p in sorted(folder.rglob("*"))
        if p.is_file() and not p.is_symlink()
    }
