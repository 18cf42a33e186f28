"""SSH lab server under load: N students at once, each driving their robot at 20 Hz.

Starts `workbench serve-ssh` on loopback (its own process, a throwaway data folder and one
user per session), then opens N SSH sessions at the same moment, the worst case of a lab
section at the start of class; then (--spread, on by default) again with the N students
arriving evenly over --spread seconds, as they do walking in. Each passes the names dialog and
drives its robot for --seconds with keys at --hz (w, a, d and space in a pattern; the app
simulates at its own 20 Hz tick). Now and then a session stops driving for a moment and
presses `p` (pause), then `p` again, timing each press until the screen shows the change
(PAUSED / running): the keypress-to-screen latency through SSH, the server and the app process.

By default two rounds, the targets: 30 students all at once, then 60 arriving over --spread
seconds; ``--sessions N...`` runs each N both ways instead (``--sessions 4 --seconds 10`` is a
quick check). After driving, each session sits idle for --idle seconds (robot stopped, no keys).

Printed for each N and arrival: time to first screen (connect to the names dialog on the
screen, p50/p95), memory per session (RSS of each app process, and PSS from
/proc/PID/smaps_rollup, which shares out the pages the processes have in common), the server
process's own growth, CPU of the server and its app processes (as % of one core and of the
whole machine), the CPU of one app process while driving and while idle (as % of one core),
and the keypress latency (p50/p95). The SSH clients run in this process on the
same machine and their CPU is printed too. The apps are forked from the server's fork server
unless --no-fork-server (the fork server's own memory is printed apart; the pages it shares
with the apps count in their PSS too). Targets on a 2-core machine: 60 sessions
arriving over 30 s held with keypress-to-screen p95 <= 150 ms; 30 at once: first screen p95
<= 3 s and keypress-to-screen p95 <= 150 ms; an idle session <= 0.3 % of a core; <= 60 MB per
session.
Figures vary from run to run.
"""

from __future__ import annotations

import argparse
import asyncio
import contextlib
import fcntl
import os
import pty
import re
import shutil
import socket
import statistics
import struct
import subprocess
import sys
import tempfile
import termios
import time
from collections.abc import AsyncIterator, Callable
from dataclasses import dataclass, field
from pathlib import Path

import asyncssh

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from procfs import children_by_parent  # noqa: E402

from workbench.door.users import add_user  # noqa: E402

PATTERN = "wwwwawwwwdww wwwwdwwwwaww "
#: a session's app in the server's log
SESSION_PID = re.compile(r"session \d+: \S+ \(\w+\) from \S+, pid (\d+)")
PROBE_EVERY = 2.0  # seconds between latency probes of one session
CLK_TCK = os.sysconf("SC_CLK_TCK")
PAGE = os.sysconf("SC_PAGE_SIZE")


@dataclass
class Result:
    first_screen: list[float] = field(default_factory=list)
    latency: list[float] = field(default_factory=list)
    keys_sent: int = 0
    failures: list[str] = field(default_factory=list)


def pct(values: list[float], q: float) -> float:
    if not values:
        return float("nan")
    ordered = sorted(values)
    return ordered[min(len(ordered) - 1, round(q * (len(ordered) - 1)))]


def free_port() -> int:
    with socket.socket() as sock:
        sock.bind(("127.0.0.1", 0))
        return sock.getsockname()[1]


# -- /proc ---------------------------------------------------------------------------------
def cpu_seconds(pid: int) -> float:
    try:
        fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
    except OSError:
        return 0.0
    return (int(fields[11]) + int(fields[12])) / CLK_TCK


def rss_bytes(pid: int) -> int:
    try:
        return int(Path(f"/proc/{pid}/statm").read_text().split()[1]) * PAGE
    except OSError:
        return 0


def pss_bytes(pid: int) -> int | None:
    try:
        for line in Path(f"/proc/{pid}/smaps_rollup").read_text().splitlines():
            if line.startswith("Pss:"):
                return int(line.split()[1]) * 1024
    except OSError:
        return None
    return None


def descendants(pid: int) -> list[int]:
    parents = children_by_parent()
    found, todo = [], [pid]
    while todo:
        kids = parents.get(todo.pop(), [])
        found += kids
        todo += kids
    return found


def is_forkserver(pid: int) -> bool:
    try:
        return b"workbench.door.forkserver" in Path(f"/proc/{pid}/cmdline").read_bytes()
    except OSError:
        return False


def apps_of(server: int) -> tuple[list[int], list[int]]:
    """The server's app processes (its children, or its fork server's), and its fork server."""
    parents = children_by_parent()
    kids = parents.get(server, [])
    forkservers = [p for p in kids if is_forkserver(p)]
    apps = [p for p in kids if p not in forkservers]
    for forkserver in forkservers:
        apps += parents.get(forkserver, [])
    return apps, forkservers


def tree_cpu(pid: int) -> float:
    """CPU seconds of the server and its live descendants (those that ended are not seen)."""
    return cpu_seconds(pid) + sum(cpu_seconds(c) for c in descendants(pid))


# -- one student ---------------------------------------------------------------------------
def student_address(index: int) -> str:
    """A loopback address of its own for each student (all of 127/8 is loopback on Linux), so
    the server sees N machines, as in a lab, not N connections from one address (which its
    per-address limit on connections not yet logged in would hold back)."""
    return f"127.0.{1 + index // 250}.{1 + index % 250}"


class Student:
    def __init__(
        self, name: str, key: asyncssh.SSHKey, port: int, result: Result, address: str,
        client: str, key_file: Path,
    ) -> None:  # fmt: skip
        self.name, self.key, self.port, self.result = name, key, port, result
        self.address = address
        self.client, self.key_file = client, key_file
        self.buffer = bytearray()
        self.arrived = asyncio.Event()
        #: CPU seconds of this student's ssh client process (OpenSSH), read as it ends
        self.client_cpu = 0.0

    def _feed(self, chunk: bytes) -> None:
        self.buffer += chunk
        self.arrived.set()

    async def _read(self, stdout) -> None:
        while chunk := await stdout.read(65536):
            self._feed(chunk)

    async def wait_for(self, needle: bytes, since: int, timeout: float) -> bool:
        deadline = time.perf_counter() + timeout
        while needle not in self.buffer[max(0, since - len(needle)) :]:
            left = deadline - time.perf_counter()
            if left <= 0:
                return False
            self.arrived.clear()
            try:
                await asyncio.wait_for(self.arrived.wait(), left)
            except TimeoutError:
                return False
        return True

    @contextlib.asynccontextmanager
    async def terminal(self) -> AsyncIterator[Callable[[bytes], None] | None]:
        """An SSH session at 80x24 whose output is fed to the buffer; yields the function
        that types bytes into it (None: it could not connect, noted as a failure)."""
        if self.client == "openssh":
            async with self._openssh() as write:
                yield write
            return
        try:
            conn = await asyncssh.connect(
                "127.0.0.1", self.port, username=self.name, client_keys=[self.key],
                known_hosts=None, agent_path=None, local_addr=(self.address, 0),
            )  # fmt: skip
        except (OSError, asyncssh.Error) as exc:
            self.result.failures.append(f"{self.name}: cannot connect: {exc}")
            yield None
            return
        try:
            proc = await conn.create_process(
                term_type="xterm-256color", term_size=(80, 24), encoding=None
            )
            reader = asyncio.create_task(self._read(proc.stdout))
            yield proc.stdin.write
            reader.cancel()
        finally:
            conn.close()

    @contextlib.asynccontextmanager
    async def _openssh(self) -> AsyncIterator[Callable[[bytes], None] | None]:
        """OpenSSH's client on a pseudo-terminal of 80x24, as a student runs it."""
        master, slave = pty.openpty()
        fcntl.ioctl(slave, termios.TIOCSWINSZ, struct.pack("HHHH", 24, 80, 0, 0))
        proc = await asyncio.create_subprocess_exec(
            "ssh", "-p", str(self.port), "-i", str(self.key_file), "-e", "none",
            "-b", self.address, "-o", "IdentitiesOnly=yes", "-o", "BatchMode=yes",
            "-o", "StrictHostKeyChecking=no", "-o", "UserKnownHostsFile=/dev/null",
            "-o", "LogLevel=ERROR", "-t", f"{self.name}@127.0.0.1",
            stdin=slave, stdout=slave, stderr=slave, start_new_session=True,
            env={**os.environ, "TERM": "xterm-256color"},
        )  # fmt: skip
        os.close(slave)
        os.set_blocking(master, False)
        loop = asyncio.get_running_loop()

        def readable() -> None:
            try:
                chunk = os.read(master, 65536)
            except (BlockingIOError, InterruptedError):
                return
            except OSError:
                chunk = b""
            if chunk:
                self._feed(chunk)
            else:
                loop.remove_reader(master)

        loop.add_reader(master, readable)
        try:
            yield lambda data: os.write(master, data)
        finally:
            self.client_cpu = cpu_seconds(proc.pid)
            loop.remove_reader(master)
            if proc.returncode is None:
                proc.terminate()
            await proc.wait()
            os.close(master)

    async def run(
        self, start: float, seconds: float, hz: float, offset: float, arrive: float,
        idle: float = 0.0,
    ) -> None:  # fmt: skip
        await asyncio.sleep(max(0.0, arrive - time.perf_counter()))
        t0 = time.perf_counter()
        async with self.terminal() as write:
            if write is None:
                return
            if not await self.wait_for(b"Who is at this robot", 0, 120):
                self.result.failures.append(f"{self.name}: no names dialog")
                return
            self.result.first_screen.append(time.perf_counter() - t0)
            mark = len(self.buffer)
            write(b"\r")
            if not await self.wait_for(b"running", mark, 60):
                tail = bytes(self.buffer[-160:])
                self.result.failures.append(f"{self.name}: no main screen; last {tail!r}")
                return
            await asyncio.sleep(max(0.0, start - time.perf_counter()))  # all drive together
            end = time.perf_counter() + seconds
            period = 1.0 / hz
            next_probe = time.perf_counter() + offset
            step = 0
            tick = time.perf_counter()
            while time.perf_counter() < end:
                if time.perf_counter() >= next_probe:
                    await self.probe(write)
                    next_probe = time.perf_counter() + PROBE_EVERY
                    tick = time.perf_counter()
                write(PATTERN[step % len(PATTERN)].encode())
                self.result.keys_sent += 1
                step += 1
                tick += period
                await asyncio.sleep(max(0.0, tick - time.perf_counter()))
            if idle > 0:  # the robot stops; the student reads, presses nothing
                write(b" ")
                await asyncio.sleep(max(0.0, end + idle - time.perf_counter()))

    async def probe(self, write: Callable[[bytes], None]) -> None:
        for key, shows in ((b"p", b"PAUSED"), (b"p", b"running")):
            await asyncio.sleep(0.1)  # let the drive keys' output settle
            mark = len(self.buffer)
            sent = time.perf_counter()
            write(key)
            if await self.wait_for(shows, mark, 5):
                self.result.latency.append(time.perf_counter() - sent)
            else:
                self.result.failures.append(f"{self.name}: {shows.decode()} not shown in 5 s")


def met(ok: bool, target: str) -> None:
    print(f"  target           {target}: {'met' if ok else 'NOT met'}")


# -- one round -----------------------------------------------------------------------------
def start_server(
    data: Path, port: int, sessions: int, fork: bool, spares: int = 0
) -> subprocess.Popen:
    """The lab server in a session of its own, as a service manager starts it: where the
    kernel weighs sessions as groups for scheduling (Linux's autogroup), a server in this
    bench's session would share one group's CPU with the bench's SSH clients."""
    first = 42000 + (port % 100) * 100
    server = subprocess.Popen(
        [sys.executable, "-m", "workbench", "serve-ssh", "--bind", "127.0.0.1",
         "--port", str(port), "--data-dir", str(data), "--public-host", "station",
         "--port-range", f"{first}-{first + 2 * sessions + 40}",
         "--max-sessions", str(max(60, sessions)), *([] if fork else ["--no-fork-server"]),
         *(["--spare-apps", str(spares)] if spares else [])],
        cwd=ROOT, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
        start_new_session=True,  # as a service runs: not in this bench's session (see below)
    )  # fmt: skip
    log = data / "ssh.log"
    deadline = time.monotonic() + 60
    while "serving on" not in (log.read_text() if log.exists() else ""):
        if server.poll() is not None or time.monotonic() > deadline:
            raise SystemExit("the SSH server did not start")
        time.sleep(0.05)
    wait_for_spares(server.pid, spares)
    return server


def wait_for_spares(server: int, count: int, timeout: float = 180.0) -> None:
    """Wait until the server's fork server has ``count`` spare apps and they have all come to
    rest at their names dialog (their CPU still for half a second)."""
    if count <= 0:
        return
    deadline = time.monotonic() + timeout
    before: float | None = None
    while time.monotonic() < deadline:
        apps = apps_of(server)[0]
        used = sum(cpu_seconds(p) for p in apps)
        if len(apps) >= count and before is not None and used - before < 0.005 * len(apps):
            return
        before = used if len(apps) >= count else None
        time.sleep(0.5)
    raise SystemExit(f"the fork server did not start {count} spare apps in {timeout:g} s")


def session_apps(data: Path, log_name: str) -> list[int]:
    """The app processes the server's log names for its sessions (spares waiting are not)."""
    log = data / log_name
    text = log.read_text(errors="replace") if log.exists() else ""
    pids = [int(m.group(1)) for m in SESSION_PID.finditer(text)]
    return [p for p in pids if Path(f"/proc/{p}").exists()]


def apps_cpu(apps: list[int]) -> float:
    return sum(cpu_seconds(p) for p in apps)


async def round_of(
    n: int,
    seconds: float,
    hz: float,
    spread: float,
    fork: bool,
    idle: float,
    client: str,
    spares: int = 0,
) -> None:
    with tempfile.TemporaryDirectory(prefix="ssh-load-") as tmp:
        data = Path(tmp)
        keys = {}
        for i in range(n):
            name = f"s{i:02d}"
            keys[name] = asyncssh.generate_private_key("ssh-ed25519")
            keys[name].write_private_key(data / f"{name}.key")
            (data / f"{name}.key").chmod(0o600)  # ssh refuses a key others can read
            add_user(data / "ssh-users.yaml", name, "student",
                     [keys[name].export_public_key().decode()])  # fmt: skip
        port = free_port()
        server = start_server(data, port, n, fork, spares)
        started = "forked from a fork server" if fork else "new processes"
        if spares:
            started += f", {spares} spare apps started ahead"
        if fork and "apps are forked" not in (data / "ssh.log").read_text():
            started = "new processes: THE FORK SERVER DID NOT START"
        time.sleep(0.5)
        base_rss = rss_bytes(server.pid)
        own_cpu0 = time.process_time()
        result = Result()
        # the drive starts for everyone once the slowest could have its first screen
        t0 = time.perf_counter()
        start = t0 + spread + max(10.0, 0.6 * n)
        students = [
            Student(name, key, port, result, student_address(i), client, data / f"{name}.key")
            for i, (name, key) in enumerate(keys.items())
        ]
        tasks = [
            asyncio.create_task(
                s.run(
                    start,
                    seconds,
                    hz,
                    offset=(i % 20) * PROBE_EVERY / 20,
                    arrive=t0 + spread * i / n,
                    idle=idle,
                )
            )
            for i, s in enumerate(students)
        ]
        await asyncio.sleep(max(0.0, start - time.perf_counter()) + 1.0)
        cpu0, wall0 = tree_cpu(server.pid), time.perf_counter()
        apps0 = session_apps(data, "ssh.log")
        app_cpu0 = apps_cpu(apps0)
        await asyncio.sleep(seconds / 2)
        forkservers = apps_of(server.pid)[1]
        apps = session_apps(data, "ssh.log")
        rss = [rss_bytes(p) for p in apps]
        pss = [v for v in (pss_bytes(p) for p in apps) if v is not None]
        fs_rss = sum(rss_bytes(p) for p in forkservers)
        fs_pss = sum(pss_bytes(p) or 0 for p in forkservers)
        server_growth = rss_bytes(server.pid) - base_rss
        await asyncio.sleep(max(0.0, seconds / 2 - 2.0))
        cpu1, wall1 = tree_cpu(server.pid), time.perf_counter()
        app_cpu1 = apps_cpu(apps0)
        idle_cpu = idle_wall = 0.0
        if idle > 0:  # from 2 s after the drive ended to 1 s before the students leave
            await asyncio.sleep(max(0.0, start + seconds + 2.0 - time.perf_counter()))
            idle_cpu0, idle_wall0 = apps_cpu(apps0), time.perf_counter()
            await asyncio.sleep(max(0.5, idle - 3.0))
            idle_cpu, idle_wall = apps_cpu(apps0) - idle_cpu0, time.perf_counter() - idle_wall0
        await asyncio.gather(*tasks, return_exceptions=True)
        own_cpu = time.process_time() - own_cpu0 + sum(s.client_cpu for s in students)
        deadline = time.monotonic() + 20
        while session_apps(data, "ssh.log") and time.monotonic() < deadline:
            await asyncio.sleep(0.1)
        left = len(session_apps(data, "ssh.log"))
        server.terminate()
        server.wait(30)
        failed = sorted({f.split(":", 1)[0] for f in result.failures})
        app_logs = {
            name: "".join(log.read_text(errors="replace")[-600:]
                          for log in sorted((data / "logs" / name).glob("*.log")))
            for name in failed[:3]
        }  # fmt: skip

    cores = os.cpu_count() or 1
    used = (cpu1 - cpu0) / (wall1 - wall0)
    mb = 1024 * 1024
    arrival = f"arriving over {spread:g} s" if spread else "ALL AT ONCE"
    print(
        f"N={n} sessions, {arrival} ({len(apps)} app processes held, {started}), "
        f"{seconds:g} s at {hz:g} Hz:"
    )
    print(
        f"  first screen     p50 {pct(result.first_screen, 0.5):.2f} s   "
        f"p95 {pct(result.first_screen, 0.95):.2f} s   max {max(result.first_screen):.2f} s"
    )
    if not spread and n == 30:
        met(pct(result.first_screen, 0.95) <= 1.0, "first screen p95 <= 1.0 s, 30 at once")
    print(
        f"  key to screen    p50 {1000 * pct(result.latency, 0.5):.0f} ms   "
        f"p95 {1000 * pct(result.latency, 0.95):.0f} ms   ({len(result.latency)} presses)"
    )
    print(
        f"  memory/session   RSS mean {statistics.mean(rss) / mb:.1f} MB  "
        f"max {max(rss) / mb:.1f} MB"
        + (f";  PSS mean {statistics.mean(pss) / mb:.1f} MB" if pss else "")
    )
    if forkservers:
        print(f"  fork server      RSS {fs_rss / mb:.1f} MB;  PSS {fs_pss / mb:.1f} MB")
    print(
        f"  server process   +{server_growth / mb:.1f} MB over its idle "
        f"{base_rss / mb:.1f} MB ({server_growth / mb / n:.2f} MB/session)"
    )
    print(
        f"  CPU server+apps  {100 * used:.0f}% of one core, {100 * used / cores:.0f}% of the "
        f"machine ({cores} cores); the SSH clients here ({client}): "
        f"{100 * own_cpu / (wall1 - start):.0f}% of one core"
    )
    per_app = (app_cpu1 - app_cpu0) / (wall1 - wall0) / max(1, len(apps0))
    print(
        f"  CPU per session  driving {100 * per_app:.2f}% of a core"
        + (
            f";  idle {100 * idle_cpu / idle_wall / max(1, len(apps0)):.2f}% of a core "
            f"(nothing moving, no keys, {idle_wall:.0f} s)"
            if idle_wall
            else ""
        )
    )
    if idle_wall:
        idle_share = idle_cpu / idle_wall / max(1, len(apps0))
        target = "CPU per session <= 1 % driving, <= 0.1 % idle"
        met(per_app <= 0.01 and idle_share <= 0.001, target)
    print(
        f"  keys sent        {result.keys_sent} ({result.keys_sent / n / seconds:.1f}/s per "
        f"session); app processes left after disconnect: {left}"
    )
    if result.failures:
        print(f"  FAILED           {len(result.failures)} of {n} sessions:")
    for failure in result.failures[:5]:
        print(f"    {failure}")
    for name, text in app_logs.items():
        print(f"    {name}'s app log: {text.strip() or '(empty)'}")
    # fmt: on


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument(
        "--sessions", type=int, nargs="+",
        help="each N both all at once and spread (default: the targets, 30 all at once and 60 "
        "spread over --spread seconds)",
    )  # fmt: skip
    parser.add_argument(
        "--idle", type=float, default=20.0,
        help="seconds each session then sits idle (robot stopped, no keys), for the idle CPU "
        "per session (0: none; default 20)",
    )  # fmt: skip
    parser.add_argument("--seconds", type=float, default=30.0)
    parser.add_argument("--hz", type=float, default=20.0)
    parser.add_argument(
        "--spread", type=float, default=30.0,
        help="also a round with the students arriving evenly over this many seconds, after the "
        "all-at-once round (0: all at once only; default 30)",
    )  # fmt: skip
    parser.add_argument(
        "--no-fork-server", action="store_true",
        help="the server starts each app as a new process (as before the fork server)",
    )  # fmt: skip
    parser.add_argument(
        "--spare-apps", type=int, default=0, metavar="N",
        help="the server keeps N apps started ahead (serve-ssh --spare-apps), started and at "
        "rest before the students come (default 0)",
    )  # fmt: skip
    parser.add_argument(
        "--client", choices=("asyncssh", "openssh"), default="asyncssh",
        help="the students' SSH client: asyncssh in this process (default), or OpenSSH's ssh "
        "on a pseudo-terminal of its own for each student, as students run it (about as much "
        "CPU on this machine, and each start costs more)",
    )  # fmt: skip
    parser.add_argument(
        "--only", choices=("together", "spread"),
        help="run only the rounds where the students arrive all at once, or only those where "
        "they arrive over --spread seconds",
    )  # fmt: skip
    args = parser.parse_args()
    if args.client == "openssh" and shutil.which("ssh") is None:
        raise SystemExit(
            "no ssh client here (apt-get install openssh-client), or --client asyncssh"
        )
    if args.sessions:
        rounds = [
            (n, spread)
            for n in args.sessions
            for spread in ((0.0, args.spread) if args.spread > 0 else (0.0,))
        ]
    else:
        rounds = [(30, 0.0), (60, args.spread)]
    if args.only == "together":
        rounds = [(n, spread) for n, spread in rounds if spread == 0]
    elif args.only == "spread":
        rounds = [(n, spread) for n, spread in rounds if spread > 0]
    print(f"{os.cpu_count()} cores; load average before: {os.getloadavg()[0]:.2f}")
    for n, spread in rounds:
        asyncio.run(
            round_of(
                n,
                args.seconds,
                args.hz,
                spread,
                not args.no_fork_server,
                args.idle,
                args.client,
                args.spare_apps,
            )
        )


if __name__ == "__main__":
    main()
