"""Protocol latency: command -> report round trips through `workbench serve` against an echo floor.

Starts, in one run, `workbench serve` (the Unity-simulator TCP role, the simulation running in
real time on the same event loop) and a bare asyncio line echo server, each as its own process,
as VIPLE and the simulator are. One client in this process sends ROUND_TRIPS command lines to
each, one at a time, waiting for the answer (the workbench answers each command with a sensor
report, the echo server with the line itself), alternating between the two in blocks so that
load from elsewhere hits both alike. It prints p50/p99 of the round trips, their ratio (target:
workbench p99 <= 3x the echo p99) and memory per connection.

The workbench also pushes a report every --report-ms (here the maximum, 1000 ms). A pushed report
cannot be told apart from an answer, so round trips are only made between pushes: the first
push arrives on connect, later ones on the same schedule, and a guard band around each expected
push is left idle and drained. Lines that still arrive unasked are counted and printed.

Memory is the resident set size of each server process (from /proc, so page-granular and only
on Linux). The echo server holds IDLE_CONNECTIONS idle connections. The workbench accepts one
driver at a time, so what is measured there is the one driver's session, and twice
IDLE_CONNECTIONS connections accepted and then refused while the driver holds the robot (each
gets the one-line JSON error and is held open for its goodbye): while held, and once closed (a
second batch that adds nothing shows the first batch's memory was kept by the allocator, not
leaked). Timing figures vary from run to run: nothing here asserts on them.
"""

from __future__ import annotations

import os
import platform
import selectors
import socket
import statistics
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass, field
from pathlib import Path

ROUND_TRIPS = 2000
#: the round trips alternate between the two servers in this many blocks
BLOCKS = 20
IDLE_CONNECTIONS = 100
REPORT_MS = 1000
#: no round trip starts this long before an expected push, nor this long after one
GUARD_BEFORE = 0.08
GUARD_AFTER = 0.03
COMMAND = (
    b'{"servos":[{"isTurn":false,"servoId":3,"servoSpeed":0},'
    b'{"isTurn":false,"servoId":5,"servoSpeed":0}]}\r\n'
)
ECHO_SERVER = """
import asyncio

async def echo(reader, writer):
    while line := await reader.readline():
        writer.write(line)
        await writer.drain()
    writer.close()

async def serve():
    server = await asyncio.start_server(echo, "127.0.0.1", 0)
    print(server.sockets[0].getsockname()[1], flush=True)
    await server.serve_forever()

asyncio.run(serve())
"""


@dataclass
class Timings:
    samples: list[float] = field(default_factory=list)
    unasked: int = 0

    @property
    def p50(self) -> float:
        return statistics.median(self.samples)

    @property
    def p99(self) -> float:
        ordered = sorted(self.samples)
        return ordered[min(len(ordered) - 1, int(0.99 * len(ordered)))]


class LineClient:
    """A blocking TCP client that reads whole lines."""

    def __init__(self, port: int) -> None:
        self.sock = socket.create_connection(("127.0.0.1", port))
        self.sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
        self.buffer = b""
        self.selector = selectors.DefaultSelector()
        self.selector.register(self.sock, selectors.EVENT_READ)

    def line(self) -> bytes:
        while b"\n" not in self.buffer:
            data = self.sock.recv(65536)
            if not data:
                raise ConnectionError("the server closed the connection")
            self.buffer += data
        line, _, self.buffer = self.buffer.partition(b"\n")
        return line

    def drain(self, seconds: float) -> int:
        """Read and drop whatever arrives within ``seconds``; how many lines that was."""
        count = self.buffer.count(b"\n")
        self.buffer = b""
        deadline = time.perf_counter() + seconds
        while True:
            left = deadline - time.perf_counter()
            if not self.selector.select(max(0.0, left)):
                if left <= 0:
                    return count
                continue
            data = self.sock.recv(65536)
            if not data:
                return count
            count += data.count(b"\n")

    def pending(self) -> bool:
        return b"\n" in self.buffer or bool(self.selector.select(0))

    def close(self) -> None:
        self.selector.close()
        self.sock.close()


class RoundTrips:
    """Round trips on one connection; with ``push_every``, only between the server's pushes."""

    def __init__(self, client: LineClient, push_every: float | None) -> None:
        self.client = client
        self.push_every = push_every
        self.timings = Timings()
        if push_every is not None:
            client.line()  # the report pushed on connect
        self.first_push = time.perf_counter()

    def run(self, count: int) -> None:
        client, timings, every = self.client, self.timings, self.push_every
        done = 0
        while done < count:
            if every is not None:
                phase = (time.perf_counter() - self.first_push) % every
                if phase < GUARD_AFTER:
                    client.drain(GUARD_AFTER - phase)
                    continue
                if phase > every - GUARD_BEFORE:
                    client.drain(every - phase + GUARD_AFTER)
                    continue
            start = time.perf_counter()
            client.sock.sendall(COMMAND)
            client.line()
            timings.samples.append(time.perf_counter() - start)
            done += 1
            if client.pending():
                timings.unasked += client.drain(0.0)


def rss_kb(pid: int) -> int | None:
    try:
        for row in Path(f"/proc/{pid}/status").read_text().splitlines():
            if row.startswith("VmRSS:"):
                return int(row.split()[1])
    except OSError:
        return None
    return None


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def start_workbench(log: Path) -> tuple[subprocess.Popen, int]:
    port = free_port()
    argv = [sys.executable, "-m", "workbench", "serve", "--tcp-port", str(port)]
    argv += ["--report-ms", str(REPORT_MS), "--bind", "127.0.0.1"]
    with open(log, "w") as err:
        proc = subprocess.Popen(argv, stdout=subprocess.DEVNULL, stderr=err)
    deadline = time.monotonic() + 20
    while "listening for VIPLE" not in log.read_text():
        if proc.poll() is not None or time.monotonic() > deadline:
            proc.kill()
            raise SystemExit(f"workbench serve did not start:\n{log.read_text()}")
        time.sleep(0.05)
    return proc, port


def start_echo() -> tuple[subprocess.Popen, int]:
    proc = subprocess.Popen([sys.executable, "-c", ECHO_SERVER], stdout=subprocess.PIPE, text=True)
    return proc, int(proc.stdout.readline())


def echo_memory(pid: int, port: int) -> tuple[int, int]:
    """RSS before and with ``IDLE_CONNECTIONS`` idle connections (each served one line)."""
    before = rss_kb(pid) or 0
    idle = [LineClient(port) for _ in range(IDLE_CONNECTIONS)]
    for client in idle:
        client.sock.sendall(COMMAND)
        client.line()
    time.sleep(0.3)
    after = rss_kb(pid) or 0
    for client in idle:
        client.close()
    return before, after


def refused_memory(pid: int, port: int) -> tuple[int, int, int, int]:
    """RSS before, while ``IDLE_CONNECTIONS`` refused connections are held for their goodbye
    and once they are gone (kB); and how many got the JSON error."""
    before = rss_kb(pid) or 0
    refused = [LineClient(port) for _ in range(IDLE_CONNECTIONS)]
    told = sum(b'"error"' in client.line() for client in refused)
    held = rss_kb(pid) or 0
    for client in refused:
        client.close()
    time.sleep(1.5)  # the goodbye lasts at most a second
    return before, held, rss_kb(pid) or 0, told


@dataclass
class Measured:
    workbench: Timings
    floor: Timings
    session_kb: int
    refused: list[tuple[int, int, int, int]]
    echo: tuple[int, int]


def measure() -> Measured:
    with tempfile.TemporaryDirectory() as tmp:
        workbench, wb_port = start_workbench(Path(tmp) / "serve.log")
        echo, echo_port = start_echo()
        try:
            idle_rss = rss_kb(workbench.pid) or 0
            driver = RoundTrips(LineClient(wb_port), REPORT_MS / 1000)
            floor = RoundTrips(LineClient(echo_port), None)
            for _ in range(BLOCKS):
                driver.run(ROUND_TRIPS // BLOCKS)
                floor.run(ROUND_TRIPS // BLOCKS)
            session_kb = (rss_kb(workbench.pid) or 0) - idle_rss
            refused = [refused_memory(workbench.pid, wb_port) for _ in range(2)]
            driver.client.close()
            floor.client.close()
            echo_rss = echo_memory(echo.pid, echo_port)
        finally:
            for proc in (workbench, echo):
                proc.terminate()
                proc.wait(timeout=10)
    return Measured(driver.timings, floor.timings, session_kb, refused, echo_rss)


def micros(seconds: float) -> str:
    return f"{seconds * 1e6:9.0f}"


def report(m: Measured) -> list[str]:
    wb, floor, n = m.workbench, m.floor, IDLE_CONNECTIONS
    lines = [f"{'':28}{'p50 µs':>9}{'p99 µs':>9}{'max µs':>9}"]
    for name, t in (("echo server (floor)", floor), ("workbench serve (report)", wb)):
        lines.append(f"{name:28}{micros(t.p50)}{micros(t.p99)}{micros(max(t.samples))}")
    ratio99 = wb.p99 / floor.p99
    verdict = "met" if ratio99 <= 3 else "NOT met"
    lines.append(
        f"workbench / floor: p50 {wb.p50 / floor.p50:.2f}x, p99 {ratio99:.2f}x "
        f"(target p99 <= 3x: {verdict})"
    )
    if wb.unasked:
        lines.append(f"  {wb.unasked} unasked lines arrived right after a round trip (dropped)")
    if not (m.echo[0] and m.refused[0][0]):
        return [*lines, "memory per connection: not available (needs /proc)"]
    before, after = m.echo
    lines += [
        "memory per connection (server RSS, kB, page-granular):",
        f"  echo server, {n} idle connections: +{after - before} kB "
        f"({(after - before) / n:.1f} each)",
        f"  workbench, its one driver (connect + {ROUND_TRIPS} round trips): +{m.session_kb} kB",
    ]
    for label, (before, held, gone, told) in zip(("first", "second"), m.refused, strict=True):
        lines.append(
            f"  workbench, {label} {n} connections accepted then refused while the driver holds "
            f"the robot ({told} got the JSON error): +{held - before} kB while held "
            f"({(held - before) / n:.1f} each), +{gone - before} kB once closed"
        )
    return lines


def main() -> None:
    print(
        f"{ROUND_TRIPS} command -> answer round trips on loopback, one at a time; "
        f"Python {platform.python_version()}, {os.cpu_count()} cores"
    )
    print("\n".join(report(measure())))


if __name__ == "__main__":
    main()
