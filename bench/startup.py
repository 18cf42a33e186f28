"""What a student's arrival and an idle session cost the SSH lab server, in CPU seconds.

Starts `workbench serve-ssh` on loopback (its own process, a throwaway data folder, one user
with a key per student, apps forked from its fork server) and measures, from /proc, CPU time
rather than wall time, so the figures hold up while other work runs on the machine:

1. --one-by-one students log in one after the other. For each: the server process's CPU for
   the SSH handshake and the login (until the client is in), its CPU for the session (the
   channel, asking the fork server for the app, passing the first screen on), and the app
   process's CPU from its fork to its first screen (the names dialog on the client's screen).
2. --students log in at the same moment, as a class does at the start of a lab: the same
   figures per student, and the wall time to the first screen (p50/p95; this one depends on
   what else the machine does).
3. the class sits at the names dialog for up to 10 s, then every student passes it and presses
   nothing for --idle seconds (the robot stands still): the CPU of one idle app (at the dialog,
   and at the main screen), of the server process and of the fork server, as % of one core.

``--compare REV`` measures the workbench of git revision REV (exported to a temporary folder)
in the same run, before this tree, and prints the ratios: a before/after under the same load.

``--profile PREFIX`` also writes cProfile statistics: ``PREFIX-after-server.prof`` (the server
process while the --students arrive; run under ``bench/profiled_app.py``; with --compare also
``PREFIX-before-server.prof``) and
``PREFIX-app.prof`` (one app from its fork to its first screen, forked from a fork server as
the lab server does), and prints their top entries. The profiler slows what it watches, so
its times are only relative.
"""

from __future__ import annotations

import argparse
import asyncio
import contextlib
import os
import re
import signal
import socket
import statistics
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass, field
from pathlib import Path

import asyncssh

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from gitrev import export  # noqa: E402
from procfs import children  # noqa: E402

from workbench.door.users import add_user  # noqa: E402

NAMES_DIALOG = b"Who is at this robot"
MAIN_SCREEN = b"running"
SESSION_LINE = re.compile(r"session \d+: (\S+) \(\w+\) from \S+, pid (\d+)")


def cpu_seconds(pid: int) -> float:
    """CPU time of a process's live threads, from the scheduler's own count (nanoseconds;
    /proc/PID/stat counts in ticks of 10 ms, too coarse for one login)."""
    total = 0
    try:
        for task in Path(f"/proc/{pid}/task").iterdir():
            with contextlib.suppress(OSError):
                total += int((task / "schedstat").read_text().split()[0])
    except OSError:
        return 0.0
    return total / 1e9


def cmdline(pid: int) -> bytes:
    try:
        return Path(f"/proc/{pid}/cmdline").read_bytes()
    except OSError:
        return b""


def free_port() -> int:
    with socket.socket() as sock:
        sock.bind(("127.0.0.1", 0))
        return sock.getsockname()[1]


def pct(values: list[float], q: float) -> float:
    if not values:
        return float("nan")
    ordered = sorted(values)
    return ordered[min(len(ordered) - 1, round(q * (len(ordered) - 1)))]


@dataclass
class Arrival:
    """One student's arrival: CPU seconds and wall seconds."""

    login_cpu: float = 0.0  # the server, handshake and login (one by one only)
    session_cpu: float = 0.0  # the server, channel to first screen (one by one only)
    app_cpu: float = 0.0  # the app, fork to first screen
    wall: float = 0.0  # connect to first screen


@dataclass
class Figures:
    one_by_one: list[Arrival] = field(default_factory=list)
    together: list[Arrival] = field(default_factory=list)
    together_server_cpu: float = 0.0  # per student
    idle_dialog: float = 0.0  # share of a core, per session at the names dialog
    idle_app: float = 0.0  # share of a core, per session at the main screen
    idle_server: float = 0.0
    idle_forkserver: float = 0.0
    failures: list[str] = field(default_factory=list)


class Student:
    def __init__(self, name: str, key: asyncssh.SSHKey, port: int, address: str) -> None:
        self.name, self.key, self.port, self.address = name, key, port, address
        self.buffer = bytearray()
        self.arrived = asyncio.Event()
        self.conn: asyncssh.SSHClientConnection | None = None
        self.proc: asyncssh.SSHClientProcess | None = None
        self.reader: asyncio.Task[None] | None = None

    async def _read(self, stdout) -> None:
        while chunk := await stdout.read(65536):
            self.buffer += chunk
            self.arrived.set()

    async def wait_for(self, needle: bytes, since: int = 0, timeout: float = 120) -> None:
        deadline = time.perf_counter() + timeout
        while needle not in self.buffer[max(0, since - len(needle)) :]:
            left = deadline - time.perf_counter()
            if left <= 0:
                raise TimeoutError(f"{self.name}: {needle.decode()!r} not shown")
            self.arrived.clear()
            await asyncio.wait_for(self.arrived.wait(), left)

    async def connect(self) -> None:
        self.conn = await asyncssh.connect(
            "127.0.0.1", self.port, username=self.name, client_keys=[self.key],
            known_hosts=None, agent_path=None, local_addr=(self.address, 0),
        )  # fmt: skip

    async def open_terminal(self) -> None:
        assert self.conn is not None
        self.proc = await self.conn.create_process(
            term_type="xterm-256color", term_size=(80, 24), encoding=None
        )
        self.reader = asyncio.create_task(self._read(self.proc.stdout))
        await self.wait_for(NAMES_DIALOG)

    async def pass_names(self) -> None:
        assert self.proc is not None
        mark = len(self.buffer)
        self.proc.stdin.write(b"\r")
        await self.wait_for(MAIN_SCREEN, mark)

    def close(self) -> None:
        if self.conn is not None:
            self.conn.close()


class Server:
    """``workbench serve-ssh`` of one tree, in its own process."""

    def __init__(self, tree: Path, data: Path, port: int, sessions: int, profile: str = ""):
        self.data = data
        first = 43000 + (port % 100) * 100
        command = [sys.executable, "-m", "workbench"]
        if profile:
            command = [sys.executable, str(ROOT / "bench" / "profiled_app.py"), profile]
        self.process = subprocess.Popen(
            [*command, "serve-ssh", "--bind", "127.0.0.1", "--port", str(port),
             "--data-dir", str(data), "--public-host", "station",
             "--port-range", f"{first}-{first + 2 * sessions + 40}",
             "--max-sessions", str(max(60, sessions))],
            cwd=tree, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
        )  # fmt: skip
        self.pid = self.process.pid
        log = data / "ssh.log"
        deadline = time.monotonic() + 60
        while "serving on" not in (log.read_text() if log.exists() else ""):
            if self.process.poll() is not None or time.monotonic() > deadline:
                raise SystemExit("the SSH server did not start")
            time.sleep(0.05)
        kids = children(self.pid)
        self.forkserver = next((p for p in kids if b"forkserver" in cmdline(p)), None)
        if self.forkserver is None:
            raise SystemExit("the SSH server started no fork server")

    def app_pids(self) -> dict[str, int]:
        """Each student's app process, from the server's log."""
        text = (self.data / "ssh.log").read_text()
        return {m.group(1): int(m.group(2)) for m in SESSION_LINE.finditer(text)}

    def stop(self) -> None:
        self.process.terminate()
        self.process.wait(30)


async def measure(tree: Path, students: int, one_by_one: int, idle: float, profile: str) -> Figures:
    figures = Figures()
    with tempfile.TemporaryDirectory(prefix="startup-") as tmp:
        data = Path(tmp)
        total = one_by_one + students
        keys = {f"s{i:02d}": asyncssh.generate_private_key("ssh-ed25519") for i in range(total)}
        for name, key in keys.items():
            add_user(data / "ssh-users.yaml", name, "student",
                     [key.export_public_key().decode()])  # fmt: skip
        port = free_port()
        server = Server(tree, data, port, total, f"{profile}-server.prof" if profile else "")
        everyone = [
            Student(name, key, port, f"127.0.{1 + i // 250}.{1 + i % 250}")
            for i, (name, key) in enumerate(keys.items())
        ]
        try:
            await asyncio.sleep(1.0)
            for student in everyone[:one_by_one]:
                arrival = Arrival()
                cpu0, t0 = cpu_seconds(server.pid), time.perf_counter()
                await student.connect()
                cpu1 = cpu_seconds(server.pid)
                await student.open_terminal()
                arrival.wall = time.perf_counter() - t0
                arrival.app_cpu = cpu_seconds(server.app_pids()[student.name])
                arrival.login_cpu = cpu1 - cpu0
                arrival.session_cpu = cpu_seconds(server.pid) - cpu1
                figures.one_by_one.append(arrival)
                student.close()
                await asyncio.sleep(0.5)
            class_ = everyone[one_by_one:]
            if profile:
                os.kill(server.pid, signal.SIGUSR1)
            cpu0 = cpu_seconds(server.pid)

            async def arrive(student: Student) -> None:
                t0 = time.perf_counter()
                try:
                    await student.connect()
                    await student.open_terminal()
                except (OSError, asyncssh.Error, TimeoutError) as exc:
                    figures.failures.append(f"{student.name}: {exc}")
                    return
                arrival = Arrival(wall=time.perf_counter() - t0)
                arrival.app_cpu = cpu_seconds(server.app_pids().get(student.name, 0))
                figures.together.append(arrival)

            await asyncio.gather(*(arrive(s) for s in class_))
            figures.together_server_cpu = (cpu_seconds(server.pid) - cpu0) / len(class_)
            if profile:
                os.kill(server.pid, signal.SIGUSR2)
            arrived = [s for s in class_ if s.proc is not None]
            # first the class sits at the names dialog (the screen they see first)
            await asyncio.sleep(2.0)
            pids = [server.app_pids()[s.name] for s in arrived]
            before = [cpu_seconds(p) for p in pids]
            t0 = time.perf_counter()
            await asyncio.sleep(min(10.0, idle))
            used = sum(cpu_seconds(p) for p in pids) - sum(before)
            figures.idle_dialog = used / (time.perf_counter() - t0) / max(1, len(pids))
            await asyncio.gather(*(s.pass_names() for s in arrived), return_exceptions=True)
            await asyncio.sleep(3.0)  # the main screens settle
            pids = [server.app_pids()[s.name] for s in arrived]
            watched = [server.pid, server.forkserver, *pids]
            before = [cpu_seconds(p) for p in watched]
            t0 = time.perf_counter()
            await asyncio.sleep(idle)
            wall = time.perf_counter() - t0
            used = [cpu_seconds(p) - b for p, b in zip(watched, before, strict=True)]
            figures.idle_server = used[0] / wall
            figures.idle_forkserver = used[1] / wall
            figures.idle_app = sum(used[2:]) / wall / max(1, len(pids))
        finally:
            for student in everyone:
                student.close()
            await asyncio.sleep(1.0)
            server.stop()
    return figures


def report(name: str, f: Figures) -> dict[str, float]:
    """Print one tree's figures; the headline ones returned for the comparison."""
    ms = 1000
    one = f.one_by_one
    together = f.together
    headline = {
        "server CPU per login (one by one)": statistics.median(a.login_cpu for a in one),
        "server CPU per session start (one by one)": statistics.median(a.session_cpu for a in one),
        "app CPU, fork to first screen (one by one)": statistics.median(a.app_cpu for a in one),
        "server CPU per student (all at once)": f.together_server_cpu,
        "app CPU, fork to first screen (all at once)": statistics.median(
            a.app_cpu for a in together
        ),
        "idle app at the names dialog, % of a core": 100 * f.idle_dialog,
        "idle app, % of a core": 100 * f.idle_app,
        "idle server process, % of a core": 100 * f.idle_server,
        "idle fork server, % of a core": 100 * f.idle_forkserver,
    }
    print(f"{name}:")
    login = headline["server CPU per login (one by one)"]
    print(
        f"  one by one ({len(one)}): server {login * ms:.1f} ms CPU for handshake and login, "
        f"{headline['server CPU per session start (one by one)'] * ms:.1f} ms for the session; "
        f"app {headline['app CPU, fork to first screen (one by one)'] * ms:.0f} ms CPU to its "
        f"first screen; first screen after {statistics.median(a.wall for a in one):.2f} s"
    )
    walls = [a.wall for a in together]
    print(
        f"  all at once ({len(together)}): server {f.together_server_cpu * ms:.0f} ms CPU per "
        f"student; app {headline['app CPU, fork to first screen (all at once)'] * ms:.0f} ms CPU"
        f" to its first screen (median); first screen p50 {pct(walls, 0.5):.2f} s, p95 "
        f"{pct(walls, 0.95):.2f} s (wall: depends on the machine's other load)"
    )
    print(
        f"  idle: an app at the names dialog {100 * f.idle_dialog:.3f}% of a core, at the main "
        f"screen {100 * f.idle_app:.3f}%; the server process "
        f"{100 * f.idle_server:.3f}%, the fork server {100 * f.idle_forkserver:.3f}%"
    )
    for failure in f.failures[:5]:
        print(f"  FAILED {failure}")
    return headline


async def profile_app(prefix: str) -> None:
    """One app forked from a fork server, profiled from its fork to its first screen."""
    from workbench.cli.ssh import WORKBENCH_APP
    from workbench.door.appproc import AppProcess, AppSpec, app_env
    from workbench.door.forkserver import ForkServer

    stats = Path(f"{prefix}-app.prof").resolve()
    env = app_env()
    env["PYTHONPATH"] = os.pathsep.join([str(ROOT / "bench"), env.get("PYTHONPATH", "")])
    env["WORKBENCH_PROFILE_TO"] = str(stats)
    preload = (*WORKBENCH_APP.preload, "profiled_app")
    forkserver = ForkServer(env, "profiled_app:from_start", preload)
    await forkserver.start()
    with tempfile.TemporaryDirectory(prefix="startup-app-") as tmp:
        data = Path(tmp)
        spec = AppSpec("s00", "student", free_port(), free_port(), "VIPLE: station",
                       data / "data", data / "runs", data / "s00")  # fmt: skip
        student = Student("s00", None, 0, "")  # type: ignore[arg-type]
        app = AppProcess([], spec.env(env), data / "app.log",
                         lambda b: (student.buffer.extend(b), student.arrived.set()),
                         forkserver=forkserver, settings=spec.settings().to_json())  # fmt: skip
        await app.start()
        await student.wait_for(NAMES_DIALOG)
        assert app.pid is not None
        os.kill(app.pid, signal.SIGUSR2)
        deadline = time.monotonic() + 30
        while not stats.exists() and time.monotonic() < deadline:
            await asyncio.sleep(0.1)
        await asyncio.sleep(0.5)
        await app.stop()
    await forkserver.close()


def show_profile(path: str, lines: int = 25) -> None:
    import pstats

    if not Path(path).exists():
        print(f"(no profile written to {path})")
        return
    print(f"\n=== {path} ===")
    stats = pstats.Stats(path)
    stats.sort_stats("tottime").print_stats(lines)
    stats.sort_stats("cumulative").print_stats(lines + 15)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--students", type=int, default=30, help="arriving at once (30)")
    parser.add_argument("--one-by-one", type=int, default=5, help="arriving one by one (5)")
    parser.add_argument("--idle", type=float, default=60.0, help="idle seconds measured (60)")
    parser.add_argument("--compare", metavar="REV", help="also measure git revision REV")
    parser.add_argument("--profile", metavar="PREFIX", help="cProfile stats to PREFIX-*.prof")
    args = parser.parse_args()
    if args.students < 1 or args.one_by_one < 1:
        parser.error("--students and --one-by-one must be at least 1")
    print(
        f"{os.cpu_count()} cores; load average before: {os.getloadavg()[0]:.2f}; "
        f"{args.one_by_one} one by one, {args.students} at once, {args.idle:g} s idle"
    )
    with tempfile.TemporaryDirectory(prefix="startup-rev-") as tmp:
        trees = {"this tree": ROOT}
        if args.compare:
            trees = {args.compare: export(args.compare, Path(tmp)), "this tree": ROOT}
        headlines = {}
        for name, tree in trees.items():
            label = "before" if name != "this tree" else "after"
            profile = f"{args.profile}-{label}" if args.profile else ""
            figures = asyncio.run(measure(tree, args.students, args.one_by_one, args.idle, profile))
            headlines[name] = report(name, figures)
    if args.compare:
        before, after = headlines[args.compare], headlines["this tree"]
        print(f"this tree / {args.compare}:")
        for key in after:
            ratio = f"x{after[key] / before[key]:.2f}" if before[key] else "-"
            print(f"  {key:45} {before[key]:8.3f} -> {after[key]:8.3f}  {ratio}")
    if args.profile:
        asyncio.run(profile_app(args.profile))
        for label in ("before", "after") if args.compare else ("after",):
            show_profile(f"{args.profile}-{label}-server.prof")
        show_profile(f"{args.profile}-app.prof")


if __name__ == "__main__":
    main()
