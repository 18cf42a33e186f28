"""What the tests of the VIPLE endpoints share: a simulation stepped by the test, free ports on
loopback, many sensors, and reports counted as they arrive."""

from __future__ import annotations

import socket
from collections.abc import Awaitable, Callable

from workbench.sim.maze import Maze
from workbench.sim.mazefile import parse_maze
from workbench.sim.sensors import SensorSpec
from workbench.sim.session import Session

# a corridor facing east, the far wall 7 blocks ahead; unity blocks are 2 units
CORRIDOR = parse_maze("##########\n#S.......#\n##########\n", source="corridor.txt")
ROOM = parse_maze("#######\n#.....#\n#..S..#\n#.....#\n#######\n", source="room.txt")


def session_for(maze: Maze = CORRIDOR, profile: str = "unity") -> Session:
    """A session without noise: every figure comes out the same each time."""
    return Session(maze, profile, noise="off")


def steps(session: Session, n: int) -> None:
    """Move the simulation on by ``n`` steps (at 60 a second) between messages."""
    for _ in range(n):
        session.step()


def free_port(outside: tuple[int, int] | None = None) -> int:
    """A port on loopback that nothing listens on now; given ``outside`` (low, high), one not
    in that range (a lab server refuses its sessions' own VIPLE ports for itself)."""
    while True:
        with socket.socket() as sock:
            sock.bind(("127.0.0.1", 0))
            port = sock.getsockname()[1]
        if outside is None or not outside[0] <= port <= outside[1]:
            return port


async def pushes_keep_their_interval(
    receive: Callable[[], Awaitable[object]],
    now: Callable[[], float],
    start: float,
    interval: float,
    count: int,
) -> None:
    """Receive the report pushed on connecting and ``count`` more, and check none came early.

    ``start`` is a time before the connection was made. The first push goes out on connecting
    and each later one is due an interval after the one before (a push missed while the loop
    was busy is skipped, never sent in a burst), so the n-th push cannot arrive before ``start``
    plus n intervals. A busy machine only makes pushes later: the check holds there too, and
    that they keep coming is the other half.
    """
    await receive()
    for n in range(1, count + 1):
        await receive()
        # a hundredth of the interval for the clock's granularity
        assert now() - start >= n * interval - interval / 100, f"push {n} came early"


def many_sensors() -> list[SensorSpec]:
    """Forty sensors: reports of about 2 KB fill the socket buffers in a few dozen reports."""
    mounts = ("front", "left", "right", "back")
    return [SensorSpec("distance", port, mounts[port % 4]) for port in range(1, 41)]
