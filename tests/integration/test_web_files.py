"""Files through the browser door: a program or maze sent into the workspace under the file
server's name rules and quotas, run records and other files downloaded, nothing outside."""

from __future__ import annotations

import json
import logging

from tests.app.support import sync
from tests.waiting import until
from workbench.files.workspace import workspace_folder
from workbench.files.workspace_files import UploadLimits

from .ssh_support import Account, moved
from .web_support import PASSWORD, web_host

MAZE = b"#####\n#S  #\n#  E#\n#####\n"


@sync
async def test_a_file_sent_lands_in_the_workspace_and_comes_back_whole(tmp_path):
    async with web_host(tmp_path, [Account("ann", password=PASSWORD)]) as host:
        browser = host.browser()
        await browser.login("ann")
        status, said = await browser.upload("corridor.txt", MAZE)
        assert (status, said["path"]) == (200, "/corridor.txt")
        workspace = workspace_folder(host.data_dir, "ann")
        assert (workspace / "corridor.txt").read_bytes() == MAZE
        status, listing = await browser.get("/files?folder=")
        names = [entry["name"] for entry in json.loads(listing)["entries"]]
        assert status == 200 and "corridor.txt" in names
        assert await browser.get("/files/corridor.txt") == (200, MAZE)
        await browser.close()


@sync
async def test_a_run_record_is_downloaded_after_driving(tmp_path):
    async with web_host(tmp_path, [Account("ann", password=PASSWORD)]) as host:
        browser = host.browser()
        await browser.login("ann")
        page = await browser.page()
        await page.start_app()
        page.send("w")
        await page.wait_until(moved, "the robot moving")
        page.send("r")  # a reset closes the run: its record is written
        runs = workspace_folder(host.data_dir, "ann") / "runs"
        record = await until(lambda: next(runs.rglob("*.jsonl"), None), "a run record")
        await until(lambda: record.stat().st_size > 0, "the record written")
        relative = record.relative_to(workspace_folder(host.data_dir, "ann")).as_posix()
        status, data = await browser.get(f"/files/{relative}")
        assert status == 200 and data.splitlines()[0] == record.read_bytes().splitlines()[0]
        # the run records are the workbench's: read, never written
        folder, name = relative.rsplit("/", 1)
        status, said = await browser.upload(name, b"{}", folder=folder)
        assert status == 400 and "run records" in said["error"], said
        await page.close()
        await browser.close()


@sync
async def test_names_the_file_server_refuses_and_a_file_past_the_cap_are_refused(tmp_path):
    async with web_host(
        tmp_path, [Account("ann", password=PASSWORD)], uploads=UploadLimits(1000, 5000, 10)
    ) as host:
        browser = host.browser()
        await browser.login("ann")
        refused = (("..", "escape.txt"), ("", ".uploading"), ("a\x01b", "x.txt"), ("", "n" * 300))
        for folder, name in refused:
            status, said = await browser.upload(name, b"x", folder=folder)
            assert status == 400, name
        status, said = await browser.upload("big.txt", b"x" * 2000)
        assert status == 400 and "at most 1 kB" in said["error"]
        workspace = workspace_folder(host.data_dir, "ann")
        assert not (workspace / "big.txt").exists()
        assert not (tmp_path / "data" / "escape.txt").exists()
        await browser.close()


@sync
async def test_a_traversal_download_is_refused_with_one_log_line(tmp_path, caplog):
    caplog.set_level(logging.INFO, "workbench.web")
    async with web_host(tmp_path, [Account("ann", password=PASSWORD)]) as host:
        browser = host.browser()
        await browser.login("ann")
        for path in ("/files/%2E%2E/ssh-users.yaml", "/files/..%2F..%2Fssh-users.yaml"):
            status, data = await browser.get(path)
            assert status == 404 and b"password" not in data, path
        refused = [r for r in caplog.records if "download refused" in r.getMessage()]
        assert len(refused) == 2 and "ann" in refused[0].getMessage()
        # an upload with another page's token is refused too
        status, _ = await browser.upload("x.txt", b"x", csrf="forged")
        assert status == 403
        await browser.close()


@sync
async def test_a_download_held_up_on_the_disk_leaves_the_server_answering(tmp_path, monkeypatch):
    """File work runs in the file threads, as SFTP's does: one student's download stuck on a
    slow disk never holds the event loop every other student is served from."""
    import asyncio
    import threading

    from workbench.web import transfer

    held, release, done = threading.Event(), threading.Event(), threading.Event()
    read = transfer.read

    def slow_read(files, path, limit):
        held.set()
        release.wait(10)  # on the event loop, this would hold every request for 10 s
        done.set()
        return read(files, path, limit)

    monkeypatch.setattr(transfer, "read", slow_read)
    accounts = [Account("ann", password=PASSWORD), Account("bob", password=PASSWORD)]
    async with web_host(tmp_path, accounts) as host:
        ann, bob = host.browser(), host.browser()
        await ann.login("ann")
        await ann.upload("corridor.txt", MAZE)
        stuck = asyncio.ensure_future(ann.get("/files/corridor.txt"))
        await until(held.is_set, "ann's download reading")
        try:
            await bob.login("bob")  # the server answers bob while ann's read is held
            status, listing = await bob.get("/files?folder=")
            assert status == 200 and json.loads(listing)["entries"] == []
            assert not done.is_set(), "bob was answered only once ann's read had ended"
        finally:
            release.set()
        assert await stuck == (200, MAZE)
        await ann.close()
        await bob.close()
