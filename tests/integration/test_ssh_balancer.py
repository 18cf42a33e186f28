"""Two ``workbench serve-ssh`` behind a real HAProxy, sharing one host key, one users file and
one PostgreSQL store, as docs/deploy.md sets them up: a student's upload, their program run in
the app and the exercise it passes follow them from server to server, and through the loss of
the server they were on."""

from __future__ import annotations

import asyncio
import contextlib
import csv
import io
import itertools
import os
import re
import shutil
import signal
import subprocess
import sys
from dataclasses import dataclass, field
from pathlib import Path

import asyncssh
import pytest

from tests.app.support import sync
from tests.sessions import free_port
from tests.students_work import own_right_wall
from tests.waiting import until
from workbench.door.users import users_path
from workbench.labs.store.store import Store
from workbench.ssh.balancer import EXAMPLE, LabBackend, haproxy_config
from workbench.ssh.hostkey import load_or_create_host_key

from .sftp_support import OpenSSH, files_under, held, needs_openssh
from .ssh_support import Account, Terminal, make_accounts, open_exercise, port_range

ROOT = Path(__file__).resolve().parents[2]
EXERCISE = "Wall following, the timed activities"
KEY = ("web-simulator", "wall-activities")
PASSED_EXIT = "[X] your program got out of the Web maze within 300 s"
ANSWERED = "[X] questions answered"
ANSWERS = ("-0.3", "0.5", "1500")  # Backward's and Forward's power, the Right90 spin in ms

#: the address the student connects from: HAProxy's PROXY header names it to the servers
STUDENT = "127.0.0.5"
#: HAProxy, also where Debian puts it off an ordinary user's PATH
HAPROXY = shutil.which("haproxy", path=f"{os.environ.get('PATH', '')}:/usr/local/sbin:/usr/sbin")
needs_haproxy = pytest.mark.skipif(
    HAPROXY is None,
    reason="no HAProxy here (Debian package haproxy; 'make test' installs it when run as root)",
)


def test_the_deployment_guide_shows_the_configuration_the_balancer_test_runs():
    guide = (ROOT / "docs" / "deploy.md").read_text()
    assert f"```\n{EXAMPLE}```" in guide


@dataclass
class LabProcess:
    """One ``workbench serve-ssh`` run as a process of its own, and what its log says."""

    name: str
    data_dir: Path
    process: subprocess.Popen
    port: int = 0

    def log(self) -> str:
        path = self.data_dir / "ssh.log"
        return path.read_text(errors="replace") if path.exists() else ""

    def logins(self, user: str) -> int:
        return self.log().count(f"login: {user} (student)")

    def sessions(self, user: str) -> list[int]:
        """The process ids of the apps this server started for ``user``'s sessions."""
        found = re.findall(rf"session \d+: {user} \(student\) from \S+, pid (\d+)", self.log())
        return [int(pid) for pid in found]

    def helpers(self) -> list[int]:
        """The fork server's and the apps' process ids, as the log gives them."""
        pids = re.findall(r"(?:fork server \(pid|, pid) (\d+)", self.log())
        return [int(pid) for pid in pids]


@dataclass
class Balancer:
    """HAProxy on loopback in front of the lab servers, and the accounts to log in with."""

    port: int
    stats_port: int
    accounts: dict[str, Account] = field(default_factory=dict)

    async def connect(self, name: str) -> asyncssh.SSHClientConnection:
        key = self.accounts[name].key
        return await asyncssh.connect(
            "127.0.0.1", self.port, username=name, client_keys=[key], known_hosts=None,
            agent_path=None, preferred_auth=["publickey"], local_addr=(STUDENT, 0),
        )  # fmt: skip

    async def servers(self) -> dict[str, tuple[str, int]]:
        """Each lab server's status in HAProxy (UP, DOWN, ...) and connections held now."""
        reader, writer = await asyncio.open_connection("127.0.0.1", self.stats_port)
        writer.write(b"show stat\n")
        await writer.drain()
        text = (await asyncio.wait_for(reader.read(), 10)).decode()
        writer.close()
        rows = csv.DictReader(io.StringIO(text.removeprefix("# ")))
        return {
            row["svname"]: (row["status"], int(row["scur"] or 0))
            for row in rows
            if row["pxname"] == "lab_servers" and row["svname"] not in ("BACKEND", "FRONTEND")
        }

    async def wait_for(self, check, what: str, timeout: float = 60) -> None:
        loop = asyncio.get_running_loop()
        deadline = loop.time() + timeout
        while not check(seen := await self.servers()):
            assert loop.time() < deadline, f"{what}: not so after {timeout:g} s: {seen}"
            await asyncio.sleep(0.1)


def start_lab(name: str, tmp_path: Path, shared: Path, db: str) -> LabProcess:
    """``serve-ssh`` on a loopback port of its choosing, with the shared host key, users file
    and course database (handed over in the environment, as docs/deploy.md advises)."""
    low, high = port_range()
    with (tmp_path / f"{name}.out").open("wb") as out:
        process = subprocess.Popen(
            [
                sys.executable, "-m", "workbench", "serve-ssh", "--bind", "127.0.0.1",
                "--port", "0", "--data-dir", str(tmp_path / name),
                "--host-key", str(shared / "ssh_host_ed25519_key"),
                "--users", str(users_path(shared)), "--port-range", f"{low}-{high}",
                "--public-host", "lab.example", "--proxy-protocol", "127.0.0.1",
            ],
            stdout=out, stderr=subprocess.STDOUT, env=os.environ | {"WORKBENCH_DB": db},
        )  # fmt: skip
    return LabProcess(name, tmp_path / name, process)


async def serving(lab: LabProcess) -> None:
    """Wait until ``lab`` listens; learn its port from its log."""

    def port() -> int:
        assert lab.process.poll() is None, (lab.data_dir.parent / f"{lab.name}.out").read_text()
        found = re.search(r"serving on 127\.0\.0\.1 port (\d+)", lab.log())
        return int(found.group(1)) if found else 0

    lab.port = await until(port, f"lab server {lab.name} listening", timeout=120, every=0.1)


def stop(process: subprocess.Popen) -> None:
    if process.poll() is None:
        process.send_signal(signal.SIGTERM)
        try:
            process.wait(20)
        except subprocess.TimeoutExpired:
            process.kill()
            process.wait()


def running(pid: int) -> bool:
    """Whether process ``pid`` still runs (a zombie has ended)."""
    try:
        state = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
    except (OSError, IndexError):
        return False
    return state not in ("Z", "X")


def end_left_over(pids: list[int]) -> None:
    """End what a killed server left running (its apps and fork server, each in a process
    group of its own), where the process is still one of ours."""
    for pid in pids:
        with contextlib.suppress(OSError):
            if Path(f"/proc/{pid}/cmdline").read_bytes().startswith(sys.executable.encode()):
                os.killpg(pid, signal.SIGKILL)


def exercise_passed(screen: str) -> bool:
    """The labs list marks the exercise passed (its title wraps in the list's column, and when
    the list is scrolled to its end the second line may be below the list's bottom border;
    the student passes no other "Wall following," exercise here)."""
    lines = screen.splitlines()
    return any(
        "[X] Wall following," in line
        and ("the timed activities" in below or below.lstrip().startswith("+-"))
        for line, below in itertools.pairwise(lines)
    )


def passed(reader_dir: Path, db: str) -> dict | None:
    """ann's saved progress in the exercise, once it has passed."""
    with Store.open(reader_dir, db=db) as store:
        progress = store.progress.of("ann").get(KEY)
    return progress if progress and progress.get("passed") is True else None


async def login_for_the_app(balancer: Balancer) -> Terminal:
    """A terminal through the balancer, trying again while a dead server's connections fail."""
    loop = asyncio.get_running_loop()
    deadline = loop.time() + 60
    while True:
        try:
            term = await Terminal.open(await balancer.connect("ann"), (100, 30))
            await term.wait_for("Who is at this robot?", "Partner", timeout=90)
            return term
        except (OSError, asyncssh.Error, AssertionError):
            if loop.time() > deadline:
                raise
            await asyncio.sleep(0.5)


# the servers, their apps, HAProxy and PostgreSQL share the machine with the rest of the suite:
# each step may wait longer than an app's usual 20 s under load


async def run_program(term: Terminal, name: str) -> None:
    """Set up the exercise, load ``~/NAME`` in the algorithm dialog, start it at top speed,
    wait until it has left the maze and the labs show the objective passed, then answer the
    exercise's questions."""
    await open_exercise(term, EXERCISE, presses=40)
    term.send("a\x1b")  # the exercise's set-up (the Web maze, its sensors), back to the run
    await term.wait_for("Run: Web Simulator lab maze (web)", timeout=60)
    term.send("g")
    await term.wait_for("Built-in", timeout=60)
    term.send(f"\t\x15~/{name}\r")  # the path field, cleared, the program's name, load
    await term.wait_for(f"{name}  (VIPLE program)", "sensors it reads", timeout=30)
    term.send("\x1b")
    await term.wait_gone("Built-in")
    term.send("x++++")  # run it from the start block at 2x, 4x, 10x, then top speed
    await term.wait_for("out at ", "the robot is out", timeout=240)
    term.send("l")
    await term.wait_for(PASSED_EXIT, timeout=30)
    term.send("\t")  # from the list to the instructions, then from field to field
    for answer in ANSWERS:
        term.send("\t" + answer + "\r")  # typed and tried with enter
    await term.wait_until(exercise_passed, "the exercise marked passed in the list", 30)


@pytest.mark.long
@needs_openssh
@needs_haproxy
@sync
async def test_a_student_moves_between_servers_behind_haproxy_and_outlives_a_crash(
    tmp_path, pg_url
):
    shared = tmp_path / "shared"
    ann = Account("ann")
    make_accounts(shared, [ann])
    load_or_create_host_key(shared / "ssh_host_ed25519_key")
    reader = tmp_path / "reader"
    labs: list[LabProcess] = []
    haproxy = None
    try:
        for name in ("one", "two"):
            labs.append(start_lab(name, tmp_path, shared, pg_url))
        await asyncio.gather(*(serving(lab) for lab in labs))
        balancer = Balancer(free_port(), free_port(), {"ann": ann})
        config = tmp_path / "haproxy.cfg"
        config.write_text(
            haproxy_config(
                f"127.0.0.1:{balancer.port}",
                [LabBackend(lab.name, f"127.0.0.1:{lab.port}") for lab in labs],
                f"ipv4@127.0.0.1:{balancer.stats_port}",
            )
        )
        haproxy_out = (tmp_path / "haproxy.out").open("wb")
        haproxy = subprocess.Popen(
            [HAPROXY, "-f", str(config), "-db"], stdout=haproxy_out, stderr=subprocess.STDOUT
        )
        haproxy_out.close()

        async def answering() -> bool:
            assert haproxy.poll() is None, (tmp_path / "haproxy.out").read_text()
            try:
                return bool(await balancer.servers())
            except OSError:
                return False

        loop = asyncio.get_running_loop()
        deadline = loop.time() + 30
        while not await answering():
            assert loop.time() < deadline, "HAProxy's stats socket did not answer"
            await asyncio.sleep(0.1)
        await balancer.wait_for(
            lambda s: all(s[lab.name][0] == "UP" for lab in labs), "both servers up"
        )

        # a connection held open on one server sends the upload to the other (leastconn)
        hold = await balancer.connect("ann")
        first = await until(
            lambda: next((lab for lab in labs if lab.logins("ann") == 1), None),
            "the held connection logged in on a server",
        )
        other = next(lab for lab in labs if lab is not first)
        assert f"login: ann (student) from {STUDENT} with key" in first.log()
        ssh = OpenSSH(balancer, tmp_path)  # OpenSSH's own scp, through the balancer
        program = own_right_wall(tmp_path)  # the student's own (the shipped example is not)
        done = await ssh.scp("ann", str(program), "@:right-wall.viple")
        assert done.status == 0, done.said
        assert "sftp: ann write /right-wall.viple" in other.log()
        assert "sftp: ann write" not in first.log()
        await until(lambda: "right-wall.viple" in held(reader, pg_url), "the upload stored", 30)

        # the app's login steered back to the first server: the other holds one connection
        await balancer.wait_for(lambda s: s[other.name][1] == 0, "the upload's connection gone")
        steer = await balancer.connect("ann")
        await until(lambda: other.logins("ann") == 2, "the second held connection on the other")
        hold.close()
        await hold.wait_closed()
        await balancer.wait_for(lambda s: s[first.name][1] == 0, "the first held connection gone")
        term = await login_for_the_app(balancer)
        assert len(first.sessions("ann")) == 1 and not other.sessions("ann")
        term.send("\r")
        await term.wait_for("distance 0.00 unit", timeout=60)
        workspace = first.data_dir / "workspaces" / "ann"
        assert (workspace / "right-wall.viple").read_bytes() == program.read_bytes()
        await run_program(term, "right-wall.viple")
        progress = await until(lambda: passed(reader, pg_url), "the exercise passed, stored", 30)
        evidence = progress["objectives"][0]["evidence"]
        assert evidence["driver"] == "VIPLE program right-wall.viple"

        # the first server dies with the student's session on it
        first.process.kill()
        first.process.wait()
        await asyncio.wait_for(term.process.wait_closed(), 30)
        await term.close()
        (app,) = first.sessions("ann")
        await until(lambda: not running(app), "the dead server's app ended with it", 30, 0.1)
        steer.close()
        await steer.wait_closed()
        again = await login_for_the_app(balancer)
        assert len(other.sessions("ann")) == 1
        await balancer.wait_for(lambda s: s[first.name][0].startswith("DOWN"), "one marked down")
        again.send("\r")
        await again.wait_for("distance 0.00 unit", timeout=60)
        again.send("l")
        await again.wait_for("esc Back", "r Ready", timeout=60)
        # the saved work read and drawn (on a busy machine the screen comes in parts)
        screen = await again.wait_until(
            lambda t: "loading saved work" not in t and PASSED_EXIT in t and ANSWERED in t,
            "the saved work read, with the exit and the answers passed",
            60,
        )
        assert EXERCISE in screen.splitlines()[0]  # reopened where the student left off
        assert exercise_passed(screen)
        there = other.data_dir / "workspaces" / "ann"
        assert (there / "right-wall.viple").read_bytes() == program.read_bytes()
        runs = files_under(workspace / "runs")
        assert runs and files_under(there / "runs") == runs  # the run record came along
        back = tmp_path / "back.viple"
        done = await ssh.scp("ann", "@:right-wall.viple", str(back))
        assert done.status == 0, done.said
        assert back.read_bytes() == program.read_bytes()
        await again.close()
    finally:
        if haproxy is not None:
            stop(haproxy)
        for lab in labs:
            stop(lab.process)
        for lab in labs:
            if lab.process.returncode == -signal.SIGKILL:
                end_left_over(lab.helpers())
