"""Browser doors on two servers that share a course database (real PostgreSQL): a file a
student sends on one is in the course store, and their next workbench on the other server
starts with it in the workspace."""

from __future__ import annotations

from tests.app.support import sync
from tests.waiting import until
from workbench.files.workspace import workspace_folder
from workbench.labs.store.store import Store

from .ssh_support import Account
from .web_support import PASSWORD, web_host

PROGRAM = b"ann's program\n"


def held(data_dir, db: str) -> dict[str, str]:
    """The course store's live files of ann, path -> sha256."""
    with Store.open(data_dir, db=db) as store:
        return {p: r.sha256 for p, r in store.workspaces.index("ann").items() if not r.deleted}


@sync
async def test_an_upload_on_one_server_is_in_the_workspace_of_the_next_session_on_another(
    tmp_path, pg_url
):
    ann = Account("ann", password=PASSWORD)
    async with (
        web_host(tmp_path / "one", [ann], db=pg_url) as one,
        web_host(tmp_path / "two", [ann], db=pg_url) as two,
    ):
        here = one.browser()
        await here.login("ann")
        status, said = await here.upload("prog.viple", PROGRAM)
        assert status == 200, said
        await until(lambda: "prog.viple" in held(one.data_dir, pg_url),
                    "the upload in the course store", timeout=30)  # fmt: skip
        there = two.browser()
        await there.login("ann")
        page = await there.page()
        await page.wait_for("Who is at this robot?", timeout=90)
        assert (workspace_folder(two.data_dir, "ann") / "prog.viple").read_bytes() == PROGRAM
        await page.close()
        for browser in (here, there):
            await browser.close()
