"""SFTP on lab servers that share a course database: what a student uploads, renames or
removes on one server is what they find on the other (OpenSSH's sftp, real PostgreSQL)."""

from __future__ import annotations

from tests.app.support import sync
from tests.waiting import until
from workbench.labs.store.workspace_sync import sync_at_start

from .sftp_support import OpenSSH, files_under, held, needs_openssh
from .ssh_support import Account, lab_host

pytestmark = needs_openssh


@sync
async def test_uploads_renames_and_removals_reach_the_other_server(tmp_path, pg_url):
    ann = Account("ann")
    (tmp_path / "prog.viple").write_bytes(b"ann's program\n")
    (tmp_path / "maze.txt").write_bytes(b"ann's maze\n")
    async with (
        lab_host(tmp_path / "one", [ann], db=pg_url, fork_server=False) as one,
        lab_host(tmp_path / "two", [ann], db=pg_url, fork_server=False) as two,
    ):
        done = await OpenSSH(one, tmp_path).sftp(
            "ann",
            "mkdir week1",
            f"put {tmp_path}/prog.viple week1/prog.viple",
            f"put {tmp_path}/maze.txt maze.txt",
        )
        assert done.status == 0, done.said
        await until(lambda: set(held(one.data_dir, pg_url)) == {"week1/prog.viple", "maze.txt"},
                    "the uploads in the course store", timeout=30)  # fmt: skip

        # the next session, on the other server, starts with them
        there = two.data_dir / "workspaces" / "ann"
        report = sync_at_start(two.data_dir, pg_url, "ann", there)
        assert not report.problems
        assert files_under(there) == {
            "week1/prog.viple": b"ann's program\n",
            "maze.txt": b"ann's maze\n",
        }

        # a folder renamed and a file removed on the second server follow back
        done = await OpenSSH(two, tmp_path).sftp("ann", "rename week1 done", "rm maze.txt")
        assert done.status == 0, done.said
        await until(lambda: set(held(two.data_dir, pg_url)) == {"done/prog.viple"},
                    "the rename and the removal in the course store", timeout=30)  # fmt: skip
        here = one.data_dir / "workspaces" / "ann"
        sync_at_start(one.data_dir, pg_url, "ann", here)
        assert files_under(here) == {"done/prog.viple": b"ann's program\n"}
