"""How late a VIPLE program's Timers end when it drives a robot over the protocol in real time.

A robot on loopback (a small TCP server here, reporting one distance sensor every 250 ms and
reading the commands) is driven by a program whose flow waits WAIT ms, prints, and waits
again, for SECONDS; a second flow prints every sensor report. Each print is stamped with the
program's clock (the client's monotonic clock when the program ran), so a wait that ended
late shows as a gap longer than WAIT between two prints. Prints the lateness's percentiles;
target: p99 <= 10 ms.

    .venv/bin/python bench/program_timers.py [--seconds S] [--wait MS]
"""

from __future__ import annotations

import argparse
import asyncio
import itertools
import statistics
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from tests.program.builder import ProgramBuilder  # noqa: E402
from workbench.cli.viple_program import _ProgramBrain  # noqa: E402
from workbench.program.pilot import load_compiled  # noqa: E402
from workbench.program.remote import RemoteProgram  # noqa: E402
from workbench.sim.profiles import get_profile  # noqa: E402
from workbench.viple.client import ClientSetup, parse_endpoint, run_client  # noqa: E402
from workbench.viple.codec import WheelPorts  # noqa: E402

REPORT_S = 0.25


def program(folder: Path, wait_ms: int) -> str:
    b = ProgramBuilder()
    main = b.panel("Main")
    b.robot(main)
    start = main.add(3, str(wait_ms))
    merge = main.add(5, "")
    timer = main.add(15, "")
    show = main.add(28, "")
    main.chain(start, merge, timer, show)
    b.link(show, merge)
    sensor = main.add(23, "Robot/IoT Controller 0", "1")
    main.chain(sensor, main.add(2, '"report " + value'), main.add(28, ""))
    return b.write(folder / "timers.viple")


async def robot(reader: asyncio.StreamReader, writer: asyncio.StreamWriter) -> None:
    """Reports every 250 ms and reads whatever comes, until the client goes."""

    async def drain_commands() -> None:
        while await reader.readline():
            pass

    reading = asyncio.create_task(drain_commands())
    try:
        for n in itertools.count():
            value = 20 + n % 5
            line = '{"sensors":[{"id":1,"name":"distance","value":' + str(value) + "}]}\r\n"
            writer.write(line.encode())
            await writer.drain()
            await asyncio.sleep(REPORT_S)
    except (ConnectionError, asyncio.CancelledError):
        pass
    finally:
        reading.cancel()
        writer.close()


async def measure(path: str, seconds: float) -> RemoteProgram:
    server = await asyncio.start_server(robot, "127.0.0.1", 0)
    port = server.sockets[0].getsockname()[1]
    remote = RemoteProgram(load_compiled(path))
    setup = ClientSetup(
        definition=None,
        profile=get_profile("web"),
        params={},
        sensors=(),
        binding={},
        endpoint=parse_endpoint(connect=f"tcp://127.0.0.1:{port}"),
        duration=seconds,
        brain=lambda: _ProgramBrain(remote, lambda text: None),
        title="timers.viple",
        ports=WheelPorts(3, 5),
    )
    async with server:
        await run_client(setup, lambda text: None)
    return remote


def percentile(values: list[float], share: float) -> float:
    ordered = sorted(values)
    return ordered[min(len(ordered) - 1, round(share * (len(ordered) - 1)))]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seconds", type=float, default=20.0)
    parser.add_argument("--wait", type=int, default=10, metavar="MS")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as folder:
        remote = asyncio.run(measure(program(Path(folder), args.wait), args.seconds))
    printed = remote.controller.printed
    ticks = [p.time for p in printed if not p.text.startswith("report")]
    reports = sum(p.text.startswith("report") for p in printed)
    late = [
        (b - a - args.wait / 1000.0) * 1000.0 for a, b in itertools.pairwise(ticks)
    ]  # ms past the Timer's own end
    if not late:
        print("no Timer ended: did the client connect?")
        return
    print(
        f"{args.wait} ms Timer over TCP on loopback, {args.seconds:g} s, "
        f"{len(late)} waits, {reports} reports"
    )
    for name, share in (("p50", 0.5), ("p90", 0.9), ("p99", 0.99)):
        print(f"  late {name}  {percentile(late, share):6.2f} ms")
    print(f"  late max  {max(late):6.2f} ms   mean {statistics.fmean(late):.2f} ms")
    p99 = percentile(late, 0.99)
    print(f"  target: p99 <= 10 ms: {'met' if p99 <= 10 else 'NOT met'}")


if __name__ == "__main__":
    main()
