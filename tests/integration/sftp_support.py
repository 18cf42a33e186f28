"""What the SFTP tests share: OpenSSH's ``sftp`` and ``scp`` run against a lab server on
loopback with an account's key, and asyncssh's SFTP client for what OpenSSH cannot send."""

from __future__ import annotations

import asyncio
import shutil
import struct
import subprocess
from dataclasses import dataclass
from pathlib import Path

import asyncssh
import pytest

from tests.waiting import until
from workbench.labs.store.store import Store

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


# -- the protocol spoken by hand, for what no client sends ------------------------------------
FXP_INIT, FXP_VERSION, FXP_OPEN, FXP_READ = 1, 2, 3, 5
FXP_STATUS, FXP_HANDLE, FXP_DATA = 101, 102, 103
FXF_READ = 1


def sftp_string(data: bytes) -> bytes:
    return struct.pack(">I", len(data)) + data


def sftp_packet(kind: int, body: bytes) -> bytes:
    return struct.pack(">IB", len(body) + 1, kind) + body


class RawSFTP(asyncssh.SSHClientSession[bytes]):
    """An SFTP client that writes the protocol's packets itself, so it can ask and not read."""

    def __init__(self) -> None:
        self.buffer = bytearray()
        self.replies: list[tuple[int, bytes]] = []
        self.arrived = asyncio.Event()

    def data_received(self, data: bytes, datatype: asyncssh.DataType) -> None:
        self.buffer += data
        while len(self.buffer) >= 4:
            (length,) = struct.unpack(">I", self.buffer[:4])
            if len(self.buffer) < 4 + length:
                break
            body = bytes(self.buffer[4 : 4 + length])
            del self.buffer[: 4 + length]
            self.replies.append((body[0], body[1:]))
        self.arrived.set()

    async def reply(self, count: int) -> tuple[int, bytes]:
        """The ``count``-th reply (from 1), once it has come."""
        await until(lambda: len(self.replies) >= count, f"reply {count}")
        return self.replies[count - 1]


def sftp_read(request: int, handle: bytes, offset: int, size: int) -> bytes:
    """A READ request's packet."""
    body = struct.pack(">I", request) + sftp_string(handle) + struct.pack(">QI", offset, size)
    return sftp_packet(FXP_READ, body)


async def raw_sftp_open(
    conn: asyncssh.SSHClientConnection, path: bytes
) -> tuple[asyncssh.SSHClientChannel[bytes], RawSFTP, bytes]:
    """An SFTP channel spoken by hand, with ``path`` open to read: the channel, its client
    (two replies in: the version and the handle) and the file's handle."""
    chan, client = await conn.create_session(RawSFTP, subsystem="sftp", encoding=None)
    chan.write(sftp_packet(FXP_INIT, struct.pack(">I", 3)))
    kind, _ = await client.reply(1)
    assert kind == FXP_VERSION
    body = struct.pack(">I", 1) + sftp_string(path) + struct.pack(">II", FXF_READ, 0)
    chan.write(sftp_packet(FXP_OPEN, body))
    kind, body = await client.reply(2)
    assert kind == FXP_HANDLE, body
    return chan, client, body[8 : 8 + struct.unpack(">I", body[4:8])[0]]


def held(data_dir, db: str) -> dict[str, str]:
    """The course store's live files of ann, path -> sha256."""
    with Store.open(data_dir, db=db) as store:
        return {p: r.sha256 for p, r in store.workspaces.index("ann").items() if not r.deleted}
