"""What OpenSSH's clients never send but a hostile one can, through asyncssh's SFTP client:
names with control and bidi characters or thousands of bytes, uploads racing for the last of a
quota on two connections, and a client gone in the middle of an upload."""

from __future__ import annotations

import logging

import asyncssh
import pytest

from tests.app.support import sync
from tests.waiting import until
from workbench.files.workspace_files import UploadLimits

from .sftp_support import files_under
from .ssh_support import Account, lab_host

CHUNK = b"v" * 32_768


async def refusal(attempt) -> str:
    with pytest.raises(asyncssh.SFTPError) as caught:
        await attempt
    return caught.value.reason


@sync
async def test_names_a_client_may_send_are_refused_with_their_reason(tmp_path):
    async with lab_host(tmp_path, [Account("ann")], fork_server=False) as host:
        conn = await host.connect("ann")
        sftp = await conn.start_sftp_client()
        cases = {
            b"bell\x07.viple": "a name cannot hold control characters (U+0007 at position 5",
            b"new\nline.viple": "a name cannot hold control characters (U+000A",
            "evil\u202eelpiv.exe".encode(): "has a bidi control character (U+202E at position 5",
            b"n" * 4096: "a path is at most 1024 bytes long (this one is 4096)",
            b"n" * 256: "a file or folder name is at most 255 bytes long (one here is 256",
            b"\xff\xfe.viple": "a file name must be UTF-8 text",
            b"../ann.viple": "'..' (the folder above) cannot be used in a path here",
            b"/a/../../x": "'..' (the folder above) cannot be used in a path here",
            b".uploading/x": ".uploading is where the server keeps uploads until they are whole",
        }
        for name, reason in cases.items():
            assert reason in await refusal(sftp.open(name, "wb")), name
        assert "'..'" in await refusal(sftp.mkdir(b"sub/../../up"))
        assert "'..'" in await refusal(sftp.rename(b"a", b"../../a"))
        assert "control characters" in await refusal(sftp.listdir(b"\x1b[2J"))
        space = host.data_dir / "workspaces" / "ann"
        assert files_under(space) == {}
        assert list(space.iterdir()) == []
        assert await sftp.realpath(b"/a/b/../../..") == b"/"
        room = await sftp.statvfs("/")  # the quota, not the server's disk
        assert (room.blocks, room.bavail, room.files, room.favail) == (
            50_000_000, 50_000_000, 2000, 2000
        )  # fmt: skip
        assert "no such file" in await refusal(sftp.statvfs("/etc"))
        conn.close()


@sync
async def test_uploads_racing_on_two_connections_cannot_pass_the_quota(tmp_path):
    limits = UploadLimits(file_size=2_000_000, quota_bytes=3_000_000)
    async with lab_host(tmp_path, [Account("ann")], fork_server=False, uploads=limits) as host:
        one, two = await host.connect("ann"), await host.connect("ann")
        sftp_one, sftp_two = await one.start_sftp_client(), await two.start_sftp_client()
        files = [await sftp_one.open("one.viple", "wb"), await sftp_two.open("two.viple", "wb")]
        refused: dict[int, str] = {}
        offset = 0
        while offset < 2_000_000 and len(refused) < 2:
            for i, file in enumerate(files):  # the two uploads take turns, chunk by chunk
                if i in refused:
                    continue
                try:
                    await file.write(CHUNK[: 2_000_000 - offset], offset)
                except asyncssh.SFTPError as exc:
                    refused[i] = exc.reason
            offset += len(CHUNK)
        for file in files:
            await file.close()
        assert len(refused) == 1, refused
        (reason,) = refused.values()
        assert "your files may take at most 3 MB on this server" in reason
        space = host.data_dir / "workspaces" / "ann"
        kept = files_under(space)
        assert len(kept) == 1 and sum(map(len, kept.values())) == 2_000_000
        usage = host.server.sftp.workspace("ann").usage
        assert (usage.bytes, usage.files, usage.reserved_bytes, usage.reserved_files) == (
            2_000_000, 1, 0, 0
        )  # fmt: skip
        assert not any((space / ".uploading").iterdir())
        one.close()
        two.close()


@sync
async def test_a_client_gone_mid_upload_leaves_no_file_and_the_quota_whole(tmp_path, caplog):
    caplog.set_level(logging.INFO, logger="workbench.ssh")
    limits = UploadLimits(file_size=3_000_000, quota_bytes=3_000_000)
    async with lab_host(tmp_path, [Account("ann")], fork_server=False, uploads=limits) as host:
        changed: list[tuple[str, str]] = []
        host.server.sftp.on_change = lambda user, path: changed.append((user, path))
        stays = await host.connect("ann")
        kept = await stays.start_sftp_client()  # keeps the workspace's count alive
        leaves = await host.connect("ann")
        sftp = await leaves.start_sftp_client()
        file = await sftp.open("half.viple", "wb")
        for i in range(40):
            await file.write(CHUNK, i * len(CHUNK))
        space = host.data_dir / "workspaces" / "ann"
        usage = host.server.sftp.workspace("ann").usage
        assert usage.reserved_bytes == 40 * len(CHUNK)
        assert len(list((space / ".uploading").iterdir())) == 1
        leaves.abort()  # the laptop's lid closed: no close of the file, no goodbye
        await until(lambda: "dropped: the client left mid-way" in caplog.text, "the drop logged")
        assert "sftp: ann write /half.viple: 1310720 bytes: dropped" in caplog.text
        assert files_under(space) == {}
        assert not any((space / ".uploading").iterdir())
        assert (usage.reserved_bytes, usage.reserved_files, usage.bytes) == (0, 0, 0)

        whole = b"w" * 3_000_000  # the whole quota, on the connection that stayed
        async with kept.open("whole.viple", "wb") as out:
            await out.write(whole)
        assert files_under(space) == {"whole.viple": whole}
        assert changed == [("ann", "whole.viple")]  # the dropped upload changed nothing
        stays.close()
