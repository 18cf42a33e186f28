"""SFTP and scp on the lab server, with OpenSSH's own clients: a student's files go to and come
from their workspace and nowhere else, within the upload limits, and the app opens them."""

from __future__ import annotations

import gzip
import logging
import os
import re

from tests.app.support import sync
from tests.waiting import until
from workbench.files.bundled import MAZE_DIR
from workbench.files.workspace_files import UploadLimits

from .sftp_support import OpenSSH, files_under, needs_openssh
from .ssh_support import Account, lab_host
from .test_ssh_isolation import type_in

pytestmark = needs_openssh

PROGRAM = b"a student's program, as VIPLE saved it\n"


@sync
async def test_a_student_puts_lists_and_gets_files_and_the_app_opens_an_upload_at_once(
    tmp_path, caplog
):
    caplog.set_level(logging.INFO, logger="workbench.ssh")
    async with lab_host(tmp_path, [Account("ann")]) as host:
        term = await host.terminal("ann")
        await term.start_app()
        ssh = OpenSSH(host, tmp_path)
        space = host.data_dir / "workspaces" / "ann"
        record = space / "runs" / "20260101-100000" / "run-001.jsonl"
        record.parent.mkdir(parents=True)
        record.write_text('{"a run": "record"}\n')  # as the app keeps one
        maze = MAZE_DIR.joinpath("web.txt").read_text()
        (tmp_path / "mine.txt").write_text(maze.replace("Web Simulator lab maze", "Ann's maze"))
        (tmp_path / "prog.viple").write_bytes(PROGRAM)

        done = await ssh.sftp(
            "ann",
            f"put {tmp_path}/mine.txt",
            "mkdir programs",
            f"put {tmp_path}/prog.viple programs/prog.viple",
            "ls -l programs",
            "cd programs",
            "pwd",
            "cd ..",
            f"get programs/prog.viple {tmp_path}/back.viple",
            f"get runs/20260101-100000/run-001.jsonl {tmp_path}/run.jsonl",
            f"-put {tmp_path}/prog.viple runs/20260101-100000/run-002.jsonl",
            "-rm runs/20260101-100000/run-001.jsonl",
            "ls",
        )
        assert done.status == 0, done.said
        assert "prog.viple" in done.stdout and "Remote working directory: /programs" in done.stdout
        assert "/runs holds the run records the workbench keeps" in done.said
        assert (tmp_path / "back.viple").read_bytes() == PROGRAM
        assert (tmp_path / "run.jsonl").read_text() == '{"a run": "record"}\n'
        assert files_under(space) == {
            "mine.txt": (tmp_path / "mine.txt").read_bytes(),
            "programs/prog.viple": PROGRAM,
            "runs/20260101-100000/run-001.jsonl": b'{"a run": "record"}\n',
        }
        await until(lambda: not (space / ".uploading").exists(), "the uploads folder removed")
        assert "sftp: ann write /programs/prog.viple: 39 bytes: done" in caplog.text
        assert "sftp: ann read /programs/prog.viple: 39 bytes: done" in caplog.text
        assert "sftp: ann write /runs/20260101-100000/run-002.jsonl: 0 bytes: refused" in (
            caplog.text
        )

        # the app, already running, loads the maze just uploaded
        term.send("m")
        await term.wait_for("Load a maze")
        await type_in(term, "mine.txt")
        await term.wait_for("the robot is on Ann's maze")
        await term.close()


@sync
async def test_scp_copies_both_ways_and_the_old_scp_protocol_is_refused_with_the_way(tmp_path):
    async with lab_host(tmp_path, [Account("ann")], fork_server=False) as host:
        ssh = OpenSSH(host, tmp_path)
        (tmp_path / "prog.viple").write_bytes(PROGRAM)
        done = await ssh.scp("ann", str(tmp_path / "prog.viple"), "@:")
        assert done.status == 0, done.said
        done = await ssh.scp("ann", "@:prog.viple", str(tmp_path / "back.viple"))
        assert done.status == 0, done.said
        assert (tmp_path / "back.viple").read_bytes() == PROGRAM

        old = await ssh.scp("ann", "-O", str(tmp_path / "prog.viple"), "@:old.viple")
        assert old.status != 0
        assert "the old scp protocol (scp -O) is not offered" in old.said
        assert f"Use 'scp -P {host.port} FILE ann@lab.example:' without -O" in old.said
        assert f"'sftp -P {host.port} ann@lab.example'" in old.said
        old = await ssh.scp("ann", "-O", "@:prog.viple", str(tmp_path / "old.viple"))
        assert old.status != 0 and "scp -O" in old.said
        assert files_under(host.data_dir / "workspaces" / "ann") == {"prog.viple": PROGRAM}


@sync
async def test_names_links_and_renames_that_would_leave_the_workspace_are_refused(tmp_path):
    async with lab_host(tmp_path, [Account("ann"), Account("ben")], fork_server=False) as host:
        ssh = OpenSSH(host, tmp_path)
        (tmp_path / "prog.viple").write_bytes(PROGRAM)
        ben = host.data_dir / "workspaces" / "ben"
        ben.mkdir(parents=True)
        (ben / "ben.viple").write_bytes(b"ben's own")
        others = lambda: {  # noqa: E731
            k: v
            for k, v in files_under(host.data_dir).items()
            if not k.startswith("workspaces/ann/")
        }
        before = others()
        long_name = "n" * 300
        done = await ssh.sftp(
            "ann",
            f"put {tmp_path}/prog.viple",
            f"-put {tmp_path}/prog.viple ../escaped.viple",
            f"-put {tmp_path}/prog.viple ../ben/ben.viple",
            f"-put {tmp_path}/prog.viple {long_name}",
            "-rename prog.viple ../../moved.viple",
            "-rename prog.viple /runs/moved.viple",
            "-ln -s /etc/passwd passwd",
            "-ln -s ../ben/ben.viple ben.viple",
            "-ln prog.viple hard.viple",
            "-get ../ben/ben.viple " + str(tmp_path / "stolen"),
            "-chmod 4755 prog.viple",
            "-chown 0 prog.viple",
            "ls -la",
        )
        said = done.said
        assert "'..' (the folder above) cannot be used in a path here" in said
        assert "a file or folder name is at most 255 bytes long (one here is 300" in said
        assert "/runs holds the run records" in said
        assert said.count("links cannot be made on this server: upload the file itself") == 3
        assert "only read and write permissions are kept here (asked for 4755)" in said
        assert "owners cannot be changed" in said
        assert not (tmp_path / "stolen").exists()
        space = host.data_dir / "workspaces" / "ann"
        assert files_under(space) == {"prog.viple": PROGRAM}
        assert not any(p.is_symlink() for p in space.rglob("*"))
        assert (space / "prog.viple").stat().st_mode & 0o7777 == 0o600
        assert others() == before


@sync
async def test_an_endless_upload_stops_at_the_file_cap_and_leaves_nothing(tmp_path, caplog):
    caplog.set_level(logging.INFO, logger="workbench.ssh")
    async with lab_host(tmp_path, [Account("ann")], fork_server=False) as host:
        ssh = OpenSSH(host, tmp_path)
        huge = tmp_path / "huge.viple"
        with huge.open("wb") as fh:
            fh.truncate(10 * 1024**3)  # 10 GiB of zeros, sparse: nothing on the disk
        done = await ssh.sftp("ann", f"put {huge}", timeout=120)
        assert done.status != 0
        assert "/huge.viple: a file may be at most 5 MB on this server" in done.said
        space = host.data_dir / "workspaces" / "ann"
        assert files_under(space) == {}
        await until(lambda: "sftp: ann write /huge.viple" in caplog.text, "the log line")
        line = next(x for x in caplog.text.splitlines() if "sftp: ann write /huge.viple" in x)
        assert "refused: /huge.viple: a file may be at most 5 MB" in line
        written = re.search(r"/huge.viple: (\d+) bytes: refused", line)
        assert written and int(written.group(1)) <= 5_000_000  # stopped at the cap


@sync
async def test_thousands_of_tiny_files_stop_at_the_file_count_quota(tmp_path):
    limits = UploadLimits(quota_files=2000)
    async with lab_host(tmp_path, [Account("ann")], fork_server=False, uploads=limits) as host:
        ssh = OpenSSH(host, tmp_path)
        many = tmp_path / "many"
        many.mkdir()
        for i in range(2100):
            (many / f"f{i:04}.txt").write_bytes(b"x")
        done = await ssh.sftp("ann", "mkdir many", f"-put {many}/* many/", timeout=300)
        assert "you may keep at most 2000 files and folders on this server" in done.said
        space = host.data_dir / "workspaces" / "ann"
        assert len(files_under(space)) == 1999  # and the folder they are in
        await until(lambda: not (space / ".uploading").exists(), "the uploads folder removed")
        done = await ssh.sftp("ann", "rm many/f0000.txt", f"put {many}/f0001.txt again.txt")
        assert done.status == 0, done.said
        assert (space / "again.txt").read_bytes() == b"x"


@sync
async def test_an_instructor_reads_every_workspace_and_changes_none(tmp_path):
    accounts = [Account("ann"), Account("ben"), Account("rivera", role="instructor")]
    async with lab_host(tmp_path, accounts, fork_server=False) as host:
        ssh = OpenSSH(host, tmp_path)
        (tmp_path / "prog.viple").write_bytes(PROGRAM)
        assert (await ssh.sftp("ann", f"put {tmp_path}/prog.viple")).status == 0
        ben = host.data_dir / "workspaces" / "ben"
        (ben / "runs" / "1").mkdir(parents=True)
        (ben / "runs" / "1" / "run-001.jsonl").write_text("{}\n")
        before = files_under(host.data_dir / "workspaces")
        done = await ssh.sftp(
            "rivera",
            "ls /",
            f"get /ann/prog.viple {tmp_path}/graded.viple",
            f"get /ben/runs/1/run-001.jsonl {tmp_path}/ben-run.jsonl",
            f"-put {tmp_path}/prog.viple /ann/prog.viple",
            f"-put {tmp_path}/prog.viple /mine.viple",
            "-rm /ann/prog.viple",
            "-mkdir /ann/new",
            "-rename /ann/prog.viple /ben/prog.viple",
        )
        assert "ann" in done.stdout and "ben" in done.stdout
        assert (tmp_path / "graded.viple").read_bytes() == PROGRAM
        assert (tmp_path / "ben-run.jsonl").read_text() == "{}\n"
        assert done.said.count("the workspaces are read-only for you") == 5
        assert files_under(host.data_dir / "workspaces") == before


@sync
async def test_file_transfers_count_against_the_users_connection_limit(tmp_path, caplog):
    from workbench.door.limits import SessionLimits

    limits = SessionLimits(connections_per_user=2)
    async with lab_host(tmp_path, [Account("ann")], limits=limits, fork_server=False) as host:
        conn = await host.connect("ann")
        first, second = await conn.start_sftp_client(), await conn.start_sftp_client()
        third = await conn.run(subsystem="sftp", check=False)
        assert third.exit_status == 1
        assert "You already have 2 file transfers open, the most one user may have" in (
            third.stderr
        )
        assert await first.listdir(".") == [".", ".."]
        first.exit()
        await first.wait_closed()
        await until(lambda: host.server.sftp.channels.get("ann") == 1, "one transfer closed")
        third_again = await conn.start_sftp_client()
        assert await third_again.listdir(".") == [".", ".."]
        second.exit()
        third_again.exit()
        conn.close()


@sync
async def test_uploads_stay_private_to_the_server_s_account(tmp_path):
    """Files 0600 and folders 0700 whatever the client asks: no other account on the server
    reads a student's program."""
    async with lab_host(tmp_path, [Account("ann")], fork_server=False) as host:
        ssh = OpenSSH(host, tmp_path)
        (tmp_path / "prog.viple").write_bytes(PROGRAM)
        os.chmod(tmp_path / "prog.viple", 0o644)
        done = await ssh.sftp("ann", "mkdir d", f"put -p {tmp_path}/prog.viple d/p.viple")
        assert done.status == 0, done.said
        space = host.data_dir / "workspaces" / "ann"
        assert (space / "d").stat().st_mode & 0o777 == 0o700
        assert (space / "d" / "p.viple").stat().st_mode & 0o777 == 0o600


@sync
async def test_a_gzip_bomb_uploaded_as_a_program_is_refused_when_the_app_opens_it(tmp_path):
    """The upload cap counts the bytes sent; what a file unpacks to is the loader's to bound."""
    bomb = tmp_path / "bomb.viple"
    bomb.write_bytes(gzip.compress(b"<Program>" + b" " * (200 << 20) + b"</Program>", 1))
    assert bomb.stat().st_size < 5_000_000  # within the upload cap
    async with lab_host(tmp_path, [Account("ann")]) as host:
        done = await OpenSSH(host, tmp_path).sftp("ann", f"put {bomb}")
        assert done.status == 0, done.said
        term = await host.terminal("ann")
        await term.start_app()
        term.send("g")
        await term.wait_for("Built-in", "Load file")
        term.send("\t")
        await type_in(term, "bomb.viple")
        await term.wait_for("decompresses to more than")
        term.send("\x1b")  # the dialog closes, the app goes on
        await term.wait_gone("Built-in")
        term.send("w")
        await term.wait_until(lambda t: "distance 0.00 unit" not in t, "the robot driven")
        await term.close()
