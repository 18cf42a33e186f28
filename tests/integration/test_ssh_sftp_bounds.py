"""What one student's SFTP can spend of the server process that carries every session,
attacked over loopback with asyncssh: reads asked for and never read back, a read asking for
more than a reply may carry, listings on the event loop, and files opened into the
descriptors kept for the live sessions."""

from __future__ import annotations

import gc
import os
import struct
import threading

import asyncssh
import pytest

from tests.app.support import sync
from tests.waiting import until
from workbench.files.workspace import workspace_folder
from workbench.files.workspace_files import WorkspaceFiles
from workbench.ssh.server import LabSession
from workbench.ssh.sftp import (
    MAX_OPEN_FILES,
    MAX_OPEN_FILES_PER_STUDENT,
    MAX_READ,
    OUT_OF_FILES,
    REQUESTS_WAITING,
)

from .sftp_support import (
    FXP_DATA,
    raw_sftp_open,
    sftp_read,
)
from .ssh_support import Account, lab_host

#: reads the attack asks for without reading a reply (the live attack asked without end)
READS = 16000
READ_SIZE = 1024
#: the file read: the live attack read a 4.9 MB upload of the student's own
FILE_SIZE = 2_000_000
#: the bytes of one READ request, as sent here
READ_REQUEST = 4 + 1 + 4 + 4 + 4 + 8 + 4
#: asyncssh's high-water mark of a channel's output buffer
HIGH_WATER = 64 * 1024


def sftp_sessions() -> list[LabSession]:
    gc.collect()
    return [o for o in gc.get_objects() if isinstance(o, LabSession) and o.sftp is not None]


@sync
async def test_reads_never_read_back_stop_the_channel_s_requests_not_grow_its_buffer(tmp_path):
    async with lab_host(tmp_path, [Account("mallory")], fork_server=False) as host:
        folder = workspace_folder(host.data_dir, "mallory")
        folder.mkdir(parents=True, exist_ok=True)
        (folder / "big.viple").write_bytes(os.urandom(FILE_SIZE))
        conn = await host.connect("mallory")
        chan, client, handle = await raw_sftp_open(conn, b"/big.viple")

        def read(request: int, offset: int, size: int) -> bytes:
            return sftp_read(request, handle, offset, size)

        # a read asking for more than a reply may carry gets what one may
        chan.write(read(2, 0, 4_000_000))
        kind, body = await client.reply(3)
        assert kind == FXP_DATA
        assert struct.unpack(">I", body[4:8])[0] == MAX_READ
        # now ask, and never read back: the client's window fills, then the server's buffer
        chan.pause_reading()
        for n in range(READS):
            chan.write(read(3 + n, (n * READ_SIZE) % (FILE_SIZE - READ_SIZE), READ_SIZE))
        (server_side,) = sftp_sessions()
        assert server_side.chan is not None and server_side.sftp is not None
        stream = server_side.sftp.stream

        def buffered() -> int:
            assert server_side.chan is not None
            return server_side.chan.get_write_buffer_size()

        def waiting() -> bool:  # the server waits for its buffer to drain, reading no requests
            return any(stream._drain_waiters.values())

        await until(lambda: waiting() or buffered() > 8 * MAX_READ, "the server stopped")
        assert buffered() <= HIGH_WATER + READ_SIZE
        # the requests past it wait, unread: what the channel takes off the client's window
        # is bounded too (the rest stays in that window, which the client is not given more of)
        await until(
            lambda: stream._read_paused or stream._recv_buf_len > 2 * REQUESTS_WAITING,
            "the channel stopped taking requests",
        )
        assert stream._recv_buf_len <= REQUESTS_WAITING + READ_REQUEST
        assert buffered() <= HIGH_WATER + READ_SIZE
        # reading again, every read is answered
        chan.resume_reading()
        await client.reply(3 + READS)
        answered = client.replies[3:]
        assert [kind for kind, _ in answered] == [FXP_DATA] * READS
        chan.close()
        conn.close()


@sync
async def test_a_listing_is_made_off_the_event_loop(tmp_path, monkeypatch):
    threads: list[int] = []
    listed = WorkspaceFiles.list

    def list_(self, parts):
        threads.append(threading.get_ident())
        return listed(self, parts)

    monkeypatch.setattr(WorkspaceFiles, "list", list_)
    async with lab_host(tmp_path, [Account("mallory")], fork_server=False) as host:
        folder = workspace_folder(host.data_dir, "mallory")
        folder.mkdir(parents=True, exist_ok=True)
        for n in range(50):
            (folder / f"f{n}.txt").write_text("x")
        conn = await host.connect("mallory")
        async with conn.start_sftp_client() as sftp:
            names = await sftp.listdir("/")
        assert "f49.txt" in names
        assert threads and threading.get_ident() not in threads
        conn.close()


@sync
async def test_files_are_not_opened_into_the_descriptors_kept_for_live_sessions(tmp_path):
    async with lab_host(tmp_path, [Account("mallory")], fork_server=False) as host:
        conn = await host.connect("mallory")
        async with conn.start_sftp_client() as sftp:
            probe = os.open(os.devnull, os.O_RDONLY)
            os.close(probe)
            limit = host.server.file_limit
            host.server.file_limit = probe + 10  # the next descriptors are the last ones
            with pytest.raises(asyncssh.SFTPFailure) as caught:
                async with sftp.open("/up.txt", "w") as f:
                    await f.write("hello")
            assert OUT_OF_FILES in caught.value.reason
            with pytest.raises(asyncssh.SFTPFailure):
                await sftp.listdir("/")
            host.server.file_limit = limit  # descriptors free again: the upload goes through
            async with sftp.open("/up.txt", "w") as f:
                await f.write("hello")
        assert (workspace_folder(host.data_dir, "mallory") / "up.txt").read_text() == "hello"
        conn.close()


@sync
async def test_a_student_s_open_files_are_capped_over_all_their_transfers(tmp_path):
    async with lab_host(tmp_path, [Account("mallory")], fork_server=False) as host:
        folder = workspace_folder(host.data_dir, "mallory")
        folder.mkdir(parents=True, exist_ok=True)
        (folder / "a.txt").write_text("a")
        conn = await host.connect("mallory")
        clients = [await conn.start_sftp_client() for _ in range(3)]
        held = []
        for sftp in clients[:2]:  # 32 files on each of two transfers: 64 in all
            held += [await sftp.open("/a.txt") for _ in range(MAX_OPEN_FILES)]
        assert len(held) == MAX_OPEN_FILES_PER_STUDENT
        with pytest.raises(asyncssh.SFTPFailure) as caught:
            await clients[2].open("/a.txt")
        assert "at most 64 files can be open at once over all your transfers" in (
            caught.value.reason
        )
        await held.pop().close()  # one closed: one may be opened, on any transfer
        again = await clients[2].open("/a.txt")
        assert await again.read() == "a"
        for sftp in clients:
            sftp.exit()
        conn.close()
