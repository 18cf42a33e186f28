"""CPU of one workbench app process while the robot drives and while it sits idle, as an SSH
session runs it.

Starts the app as the SSH server does (under Textual's web driver, packets over pipes, the
student's VIPLE TCP and WebSocket endpoints on, 80x24, the names dialog at start), with a
session's settings given as ``python -m workbench`` options (which every revision takes, so
``--compare`` can start an older one the same way), passes the names dialog, and then, for each
mode of --modes:

  * ``ssh``: the key pattern of ``bench/ssh_load.py`` at --hz keys a second (forward, a turn now
    and then, stop now and then), as the load station sends it, for --seconds;
  * ``drive``: ``w`` once, then a turn (``a`` or ``d``) every 1.5 s, no other keys, --seconds;
  * ``idle``: no key at all for --idle-seconds (nothing moves): what a student who has logged
    in and is reading costs the server. After a driving mode the robot is stopped first (space)
    and its run stays open, recorded as it stands.

The app ticks its simulation at its own 20 Hz. The bench answers the app's question whether
the terminal draws synchronized updates as most terminals do (yes), so the app writes its frames
as a student's terminal gets them. Printed per mode: the app process's CPU (user + system, from
/proc) per second of the mode, as % of one core (at 1x speed, CPU seconds per simulated and drawn
second); the screen output in bytes and in writes a second (each write the server hands to the
SSH channel: one SSH packet); and the CPU of this bench's own process, which does the server's
part of a session without SSH (reads the app's packets, hands on the screen output, sends the
keys). Each of --runs runs is a fresh process; the medians are printed last.

``--compare REV`` measures the workbench of git revision REV (exported to a temporary folder)
in the same run, alternating with this tree, and prints both medians and their ratios (app CPU,
and the server's part): a before/after taken under the same load from other processes on the
machine. The older revision's app is read with that revision's own server code
(``workbench/door/appproc.py``, with the packets module it imports), so a change there is measured
too.

``--profile PREFIX`` runs the app under cProfile, switched on only for the measured stretch of
each mode (start-up and the names dialog are left out; the figures are then only relative), and
writes ``PREFIX-MODE.prof``, printing the top functions by own and total time.
"""

from __future__ import annotations

import argparse
import asyncio
import contextlib
import importlib
import importlib.util
import os
import re
import signal
import socket
import statistics
import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from gitrev import export  # noqa: E402

from workbench.door.appproc import AppProcess, AppSpec  # noqa: E402

CLK_TCK = os.sysconf("SC_CLK_TCK")
SSH_PATTERN = "wwwwawwwwdww wwwwdwwwwaww "
SETTLE = 1.0  # seconds of the mode before the CPU is counted
#: the app asks whether the terminal draws synchronized updates; most terminals answer yes
SYNC_QUERY = b"\x1b[?2026$p"
SYNC_ANSWER = b"\x1b[?2026;2$y"
MODES = ("ssh", "drive", "idle")


def cpu_seconds(pid: int) -> float:
    fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / CLK_TCK


def free_port() -> int:
    with socket.socket() as sock:
        sock.bind(("127.0.0.1", 0))
        return sock.getsockname()[1]


class Screen:
    """The app's screen output as it arrives."""

    def __init__(self) -> None:
        self.buffer = bytearray()
        self.bytes = 0
        self.writes = 0
        self.arrived = asyncio.Event()
        #: sends bytes to the app as typed (set once the app runs)
        self.answer: Callable[[bytes], None] | None = None

    def feed(self, data: bytes) -> None:
        self.bytes += len(data)
        self.writes += 1
        if SYNC_QUERY in data and self.answer is not None:
            self.answer(SYNC_ANSWER)
        self.buffer += data
        if len(self.buffer) > 1 << 20:
            del self.buffer[: -(1 << 16)]
        self.arrived.set()

    async def wait_for(self, needle: bytes, timeout: float) -> None:
        deadline = time.monotonic() + timeout
        while needle not in self.buffer:
            left = deadline - time.monotonic()
            if left <= 0:
                raise SystemExit(f"the app never showed {needle.decode()!r}")
            self.arrived.clear()
            with contextlib.suppress(TimeoutError):
                await asyncio.wait_for(self.arrived.wait(), left)


async def drive(app: AppProcess, mode: str, seconds: float, hz: float) -> None:
    """Send the mode's keys for ``seconds``."""
    period = 1.0 / hz
    start = time.perf_counter()
    end = start + seconds
    step = 0
    tick = start
    turn_at = start + 1.5
    if mode == "drive":
        app.send_keys(b"w")
    while (now := time.perf_counter()) < end:
        if mode == "ssh":
            app.send_keys(SSH_PATTERN[step % len(SSH_PATTERN)].encode())
            step += 1
            tick += period
        elif mode == "drive" and now >= turn_at:
            app.send_keys(b"ad"[step % 2 : step % 2 + 1])
            step += 1
            turn_at += 1.5
            tick = min(turn_at, now + 0.1)
        else:
            tick = min(turn_at if mode == "drive" else end, now + 0.1)
        await asyncio.sleep(max(0.0, tick - time.perf_counter()))


async def one_run(
    tree: Path, modes: list[str], seconds: float, idle_seconds: float, hz: float,
    profile: str | None,
) -> dict[str, dict[str, float]]:  # fmt: skip
    """One fresh app process of the workbench in ``tree``: each mode's CPU and output rate."""
    with tempfile.TemporaryDirectory(prefix="tui-cpu-") as tmp:
        data = Path(tmp)
        spec = AppSpec(
            user="station",
            role="student",
            tcp_port=free_port(),
            ws_port=free_port(),
            hint="VIPLE: station",
            data_dir=data / "data",
            record_dir=data / "runs",
            workspace=data,
        )
        command: tuple[str, ...] = (sys.executable, "-m", "workbench")
        stats = data / "app.prof"
        if profile:
            command = (sys.executable, str(ROOT / "bench" / "profiled_app.py"), str(stats))
        env = spec.env()
        env["TEXTUAL_DRIVER"] = tree_driver(tree)
        screen = Screen()
        here = os.getcwd()
        os.chdir(tree)  # ``python -m workbench`` imports the tree it is started in
        try:
            server_side = tree_app_process(tree)
            argv = [*command, *app_options(spec)]
            app = server_side(argv, env, data / "app.log", screen.feed)
            await app.start()
        finally:
            os.chdir(here)
        screen.answer = app.send_keys
        results: dict[str, dict[str, float]] = {}
        try:
            await screen.wait_for(b"Who is at this robot", 60)
            screen.buffer.clear()
            app.send_keys(b"\r")
            await screen.wait_for(b"running", 60)
            await asyncio.sleep(0.5)
            pid = app.pid
            assert pid is not None
            driven = False
            for mode in modes:
                if mode == "idle" and driven:
                    app.send_keys(b" ")  # the robot stops and then stands still
                driven = driven or mode != "idle"
                length = idle_seconds if mode == "idle" else seconds
                settle = asyncio.create_task(drive(app, mode, SETTLE + length, hz))
                await asyncio.sleep(SETTLE)
                if profile:
                    os.kill(pid, signal.SIGUSR1)
                cpu0, bytes0, t0 = cpu_seconds(pid), screen.bytes, time.perf_counter()
                writes0, own0 = screen.writes, time.process_time()
                await settle
                cpu1, bytes1, t1 = cpu_seconds(pid), screen.bytes, time.perf_counter()
                writes1, own1 = screen.writes, time.process_time()
                if profile:
                    with contextlib.suppress(FileNotFoundError):
                        stats.unlink()
                    os.kill(pid, signal.SIGUSR2)
                    deadline = time.monotonic() + 30
                    while not stats.exists() and time.monotonic() < deadline:
                        await asyncio.sleep(0.1)
                    await asyncio.sleep(0.5)
                    if stats.exists():
                        stats.replace(f"{profile}-{mode}.prof")  # the last of each mode
                label = mode if mode not in results else f"{mode} again"
                results[label] = {
                    "cpu": (cpu1 - cpu0) / (t1 - t0),
                    "bytes": (bytes1 - bytes0) / (t1 - t0),
                    "writes": (writes1 - writes0) / (t1 - t0),
                    "server": (own1 - own0) / (t1 - t0),
                }
        finally:
            await app.stop(grace=10.0)
        return results


def app_options(spec: AppSpec) -> list[str]:
    """A session's settings as the command line's options."""
    settings = spec.settings()
    return [
        "--student", spec.user,
        "--ask-partner",
        "--role", settings.role,
        "--tcp-port", str(settings.tcp_port),
        "--ws-url", str(settings.ws_url),
        "--ws-when-asked",
        "--connect-hint", settings.connect_hint,
        "--data-dir", str(settings.data_dir),
        "--record-dir", str(settings.record_dir),
        "--workspace", str(settings.workspace),
    ]  # fmt: skip


def _appproc_folder(tree: Path) -> Path:
    """Where ``tree`` keeps ``appproc.py``: ``workbench/door`` now, ``workbench/ssh`` before."""
    door = tree / "workbench" / "door"
    return door if (door / "appproc.py").is_file() else tree / "workbench" / "ssh"


def tree_app_process(tree: Path) -> type[AppProcess]:
    """The server side of a session (``AppProcess``) as the workbench in ``tree`` has it."""
    if tree == ROOT:
        return AppProcess
    folder = _appproc_folder(tree)
    name = f"_{folder.name}_of_{len(sys.modules)}"
    found = importlib.util.spec_from_file_location(
        name, folder / "__init__.py", submodule_search_locations=[str(folder)]
    )
    assert found is not None and found.loader is not None
    package = importlib.util.module_from_spec(found)
    sys.modules[name] = package
    found.loader.exec_module(package)
    return importlib.import_module(f"{name}.appproc").AppProcess


def tree_driver(tree: Path) -> str:
    """The Textual driver the lab server of ``tree`` runs its apps with."""
    source = (_appproc_folder(tree) / "appproc.py").read_text()
    found = re.search(r'^DRIVER = "([^"]+)"', source, re.MULTILINE)
    return found.group(1) if found else "textual.drivers.web_driver:WebDriver"


def show_profile(path: str) -> None:
    import pstats

    stats = pstats.Stats(path)
    stats.sort_stats("tottime").print_stats(25)
    stats.sort_stats("cumulative").print_stats(40)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seconds", type=float, default=20.0, help="driving time per run")
    parser.add_argument("--idle-seconds", type=float, default=30.0, help="idle time per run")
    parser.add_argument("--hz", type=float, default=20.0, help="keys a second (ssh mode)")
    parser.add_argument("--modes", nargs="+", choices=MODES, default=["idle", "ssh"])
    parser.add_argument("--runs", type=int, default=3, help="fresh app processes")
    parser.add_argument("--compare", metavar="REV", help="also measure git revision REV")
    parser.add_argument("--profile", metavar="PREFIX", help="cProfile stats to PREFIX-MODE.prof")
    args = parser.parse_args()
    runs = 1 if args.profile else args.runs
    print(
        f"app CPU: web driver, 80x24, unity maze; modes {', '.join(args.modes)} "
        f"(ssh keys at {args.hz:g}/s, {args.seconds:g} s; idle {args.idle_seconds:g} s) x {runs}"
    )
    with tempfile.TemporaryDirectory(prefix="tui-cpu-rev-") as tmp:
        trees = {"this tree": ROOT}
        if args.compare:
            trees = {args.compare: export(args.compare, Path(tmp)), "this tree": ROOT}
        results: dict[str, list[dict[str, dict[str, float]]]] = {name: [] for name in trees}
        for i in range(runs):
            for name, tree in trees.items():
                r = asyncio.run(
                    one_run(
                        tree, args.modes, args.seconds, args.idle_seconds, args.hz, args.profile
                    )
                )
                results[name].append(r)
                shown = "   ".join(
                    f"{mode} {100 * v['cpu']:5.2f}% ({v['bytes'] / 1000:.2f} KB/s in "
                    f"{v['writes']:.1f} writes/s; server part {100 * v['server']:.2f}%)"
                    for mode, v in r.items()
                )
                print(f"  run {i + 1} {name:>10}: {shown}")
    medians = {
        name: {
            mode: {key: statistics.median(r[mode][key] for r in rs) for key in rs[0][mode]}
            for mode in rs[0]
        }
        for name, rs in results.items()
    }
    for name, by_mode in medians.items():
        shown = "   ".join(
            f"{mode} {100 * v['cpu']:5.2f}% of a core (server part {100 * v['server']:.2f}%, "
            f"{v['writes']:.1f} writes/s)"
            for mode, v in by_mode.items()
        )
        print(f"  median {name:>10}: {shown}")
    if args.compare:
        before, after = medians[args.compare], medians["this tree"]

        def ratio(mode: str, key: str) -> str:
            was = before[mode][key]
            return f"x{after[mode][key] / was:.2f}" if was else "-"

        shown = "   ".join(
            f"{mode} app {ratio(mode, 'cpu')} server part {ratio(mode, 'server')}" for mode in after
        )
        print(f"  this tree / {args.compare}: {shown}")
    if args.profile:
        for mode in dict.fromkeys(args.modes):
            if Path(f"{args.profile}-{mode}.prof").exists():
                print(f"\n=== profile: {mode} ===")
                show_profile(f"{args.profile}-{mode}.prof")


if __name__ == "__main__":
    main()
