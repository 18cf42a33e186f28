"""The Unity-simulator role's timing: how regular the pushed reports are, and how much of the
event loop a flood of commands leaves to the rest of the program, in one run.

1. A client connects and reads the reports pushed every 50 ms and every 100 ms for two seconds
   each, sending nothing: it prints the pushes per second against the configured rate and the
   largest gap between two pushes against the interval.
2. A task that wakes every 5 ms counts its turns for a second with the loop idle, and again
   while 20,000 command lines arrive as fast as the client can send them: it prints the turns
   per second in each case and their ratio (target: at least 20 turns a second during the
   flood, a tenth of the 200 a task waking every 5 ms could have), the commands taken per
   second, and the replies and pushes read (or dropped while the client was behind).

Timing figures vary with the machine and its load; nothing here asserts on them. The tests
check the order of events instead (tests/integration/test_tcp_server.py).
"""

from __future__ import annotations

import asyncio
import itertools

from workbench.sim.mazefile import parse_maze
from workbench.sim.session import Session
from workbench.viple.tcp_server import TcpConfig, TcpServer

ROOM = parse_maze("#######\n#.....#\n#..S..#\n#.....#\n#######\n", source="room.txt")
STOP = b'{"servos":[{"isTurn":false,"servoId":-1,"servoSpeed":0}]}\r\n'
FLOOD = 20_000


async def pushes(report_ms: int, seconds: float = 2.0) -> tuple[float, float]:
    """Pushes per second and the largest gap between two pushes, in seconds."""
    session = Session(ROOM, "unity", noise="off")
    async with TcpServer(session, TcpConfig(port=0, report_ms=report_ms)) as server:
        reader, writer = await asyncio.open_connection("127.0.0.1", server.port)
        loop = asyncio.get_running_loop()
        await reader.readline()
        times = [loop.time()]
        while times[-1] - times[0] < seconds:
            await reader.readline()
            times.append(loop.time())
        writer.close()
    gaps = [b - a for a, b in itertools.pairwise(times)]
    return (len(times) - 1) / (times[-1] - times[0]), max(gaps)


async def turns(seconds: float) -> int:
    """Turns a task waking every 5 ms gets in ``seconds`` of an idle loop."""
    count = 0
    loop = asyncio.get_running_loop()
    end = loop.time() + seconds
    while loop.time() < end:
        await asyncio.sleep(0.005)
        count += 1
    return count


async def flood() -> tuple[float, float, float, int]:
    """Turns per second of the waking task during the flood, the flood's length in seconds,
    commands per second, and the lines read plus those dropped."""
    session = Session(ROOM, "unity", noise="off")
    async with TcpServer(session, TcpConfig(port=0, report_ms=50)) as server:
        reader, writer = await asyncio.open_connection("127.0.0.1", server.port)
        await reader.readline()
        count = 0
        lines = 0

        async def ticker() -> None:
            nonlocal count
            while True:
                await asyncio.sleep(0.005)
                count += 1

        async def read() -> None:
            nonlocal lines
            while await reader.readline():
                lines += 1

        tasks = [asyncio.create_task(ticker()), asyncio.create_task(read())]
        loop = asyncio.get_running_loop()
        start = loop.time()
        for _ in range(10):
            writer.write(STOP * (FLOOD // 10))
            await writer.drain()
        while server.status.messages_in < FLOOD:
            await asyncio.sleep(0.001)
        elapsed = loop.time() - start
        ticks = count
        while lines + server.status.dropped < FLOOD:
            await asyncio.sleep(0.01)
        for task in tasks:
            task.cancel()
        writer.close()
        return ticks / elapsed, elapsed, FLOOD / elapsed, lines + server.status.dropped


async def measure() -> None:
    for report_ms in (50, 100):
        rate, gap = await pushes(report_ms)
        print(
            f"pushes every {report_ms} ms: {rate:6.1f} a second (configured "
            f"{1000 / report_ms:.0f}), largest gap {gap * 1000:.0f} ms"
        )
    idle = await turns(1.0)
    during, elapsed, commands, answered = await flood()
    print(f"5 ms task, idle loop:      {idle:6.0f} turns a second")
    print(f"5 ms task, during a flood: {during:6.0f} turns a second over {elapsed:.2f} s")
    print(f"flood / idle:              {during / idle:6.2f}   (target: >= 20 turns a second)")
    print(f"commands taken:            {commands:6.0f} a second; {answered} replies and pushes")


def main() -> None:
    asyncio.run(measure())


if __name__ == "__main__":
    main()
