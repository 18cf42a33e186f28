"""CPU of one workbench app process while the robot drives, as an SSH session runs it.

Starts the app the way the SSH server does (``python -m workbench`` under Textual's web driver,
packets over pipes, the student's VIPLE TCP and WebSocket endpoints on, 80x24, the names dialog
at start), passes the names dialog, and drives the robot on the bundled Unity maze for
--seconds:

  * ``--keys ssh`` (default): the key pattern of ``bench/ssh_load.py`` at --hz keys a second
    (forward, a turn now and then, stop now and then), as the load station sends it;
  * ``--keys drive``: ``w`` once, then a turn (``a`` or ``d``) every 1.5 s, no other keys.

The app ticks its simulation at its own 20 Hz either way. Printed: the app process's CPU
(user + system, from /proc) per second of driving, i.e. CPU seconds per simulated-and-drawn
second at 1x speed, as % of one core; the screen output in bytes a second. Each of --runs runs
is a fresh process; the median is printed last.

``--profile FILE`` runs the app under cProfile (slower; the figures are then only relative)
and writes its stats to FILE at the end, printing the top functions by own and total time.
"""

from __future__ import annotations

import argparse
import asyncio
import contextlib
import os
import socket
import statistics
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from workbench.ssh.appproc import AppProcess, AppSpec  # noqa: E402

CLK_TCK = os.sysconf("SC_CLK_TCK")
SSH_PATTERN = "wwwwawwwwdww wwwwdwwwwaww "
SETTLE = 1.0  # seconds of driving before the CPU is counted


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
        self.arrived = asyncio.Event()

    def feed(self, data: bytes) -> None:
        self.bytes += len(data)
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


async def one_run(seconds: float, hz: float, keys: str, profile: str | None) -> dict[str, float]:
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
        command = None
        if profile:
            command = (sys.executable, "-m", "cProfile", "-o", profile, "-m", "workbench")
        screen = Screen()
        app = AppProcess(spec.argv(command), spec.env(), data / "app.log", screen.feed)
        await app.start()
        try:
            await screen.wait_for(b"Who is at this robot", 60)
            screen.buffer.clear()
            app.send_keys(b"\r")
            await screen.wait_for(b"running", 60)
            await asyncio.sleep(0.5)
            pid = app.pid
            assert pid is not None
            period = 1.0 / hz
            start = time.perf_counter()
            end = start + SETTLE + seconds
            cpu0 = bytes0 = t0 = None
            step = 0
            tick = start
            turn_at = start + 1.5
            if keys == "drive":
                app.send_keys(b"w")
            while (now := time.perf_counter()) < end:
                if cpu0 is None and now >= start + SETTLE:
                    cpu0, bytes0, t0 = cpu_seconds(pid), screen.bytes, now
                if keys == "ssh":
                    app.send_keys(SSH_PATTERN[step % len(SSH_PATTERN)].encode())
                    step += 1
                    tick += period
                elif now >= turn_at:
                    app.send_keys(b"ad"[step % 2 : step % 2 + 1])
                    step += 1
                    turn_at += 1.5
                    tick = min(turn_at, now + 0.1)
                else:
                    tick = min(turn_at, now + 0.1)
                await asyncio.sleep(max(0.0, tick - time.perf_counter()))
            cpu1, bytes1, t1 = cpu_seconds(pid), screen.bytes, time.perf_counter()
        finally:
            await app.stop(grace=10.0)
        assert cpu0 is not None and bytes0 is not None and t0 is not None
        return {"cpu": (cpu1 - cpu0) / (t1 - t0), "bytes": (bytes1 - bytes0) / (t1 - t0)}


def show_profile(path: str) -> None:
    import pstats

    stats = pstats.Stats(path)
    stats.sort_stats("tottime").print_stats(30)
    stats.sort_stats("cumulative").print_stats(50)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seconds", type=float, default=20.0, help="driving time per run")
    parser.add_argument("--hz", type=float, default=20.0, help="keys a second (--keys ssh)")
    parser.add_argument("--keys", choices=("ssh", "drive"), default="ssh")
    parser.add_argument("--runs", type=int, default=3, help="fresh app processes")
    parser.add_argument("--profile", metavar="FILE", help="run under cProfile, stats to FILE")
    args = parser.parse_args()
    runs = 1 if args.profile else args.runs
    print(
        f"app CPU while driving: web driver, 80x24, unity maze, keys {args.keys}"
        f"{f' at {args.hz:g}/s' if args.keys == 'ssh' else ''}, {args.seconds:g} s x {runs}"
    )
    results = []
    for i in range(runs):
        r = asyncio.run(one_run(args.seconds, args.hz, args.keys, args.profile))
        results.append(r)
        cpu, out = 100 * r["cpu"], r["bytes"] / 1000
        print(f"  run {i + 1}: CPU {cpu:5.2f}% of a core   {out:6.2f} KB/s")
    cpu = statistics.median(r["cpu"] for r in results)
    out = statistics.median(r["bytes"] for r in results)
    print(f"  median: CPU {100 * cpu:5.2f}% of a core   {out / 1000:6.2f} KB/s")
    if args.profile:
        show_profile(args.profile)


if __name__ == "__main__":
    main()
