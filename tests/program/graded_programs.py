"""Small VIPLE programs a grading run meets: a right-wall follower for the Web Simulator
profile (started by a key, or from the start), and two hostile ones."""

from __future__ import annotations

from pathlib import Path

from tests.program.builder import ProgramBuilder
from workbench.program.keys import KEY_NUMBERS

ROBOT = "Robot/IoT Controller 0"


def right_wall(path: Path, start_key: str | None = None, viple3: bool = False) -> str:
    """A right-wall follower: distance sensor on port 1 (right), touch sensor on port 2
    (front). With ``start_key`` it waits for that key before it moves. ``viple3`` writes it
    as VIPLE 3.1 saved programs: gzip-compressed XML, the robot named "My Robot 0"."""
    robot = "My Robot 0" if viple3 else ROBOT
    b = ProgramBuilder(version="3.1.0" if viple3 else "4.0.0.1")
    b.var("mode", "System.String")
    m = b.panel("Main")
    if viple3:
        m.add(19, "localhost", "8124", "WSS")
    else:
        b.robot(m)
    start = m.add(3, '"fwd"')
    m.chain(start, m.add(1, "mode"), _drive(m, 0.5, 0.5, robot))
    if start_key is not None:
        b.link(m.add(13, str(KEY_NUMBERS[start_key])), start)
    # an opening on the right: turn into it, drive on, then follow the wall again
    sensor = m.add(23, robot, "1")
    gap = m.add(6, 'value > 60 && state.mode == "fwd"')
    b.link(sensor, gap)
    turn = [m.add(3, '"turn"'), m.add(1, "mode"), m.add(3, "450"), m.add(15, "")]
    turn += [
        _drive(m, 0.2, -0.2, robot),
        m.add(3, "1500"),
        m.add(15, ""),
        _drive(m, 0.5, 0.5, robot),
    ]
    turn += [m.add(3, "1000"), m.add(15, ""), m.add(3, '"fwd"'), m.add(1, "mode")]
    m.chain(*turn)
    b.link(gap, turn[0], pin=0)
    # a wall ahead: turn left on the spot
    bump = [
        m.add(22, robot, "2"),
        m.add(3, '"turn"'),
        m.add(1, "mode"),
        _drive(m, -0.2, 0.2, robot),
    ]
    bump += [m.add(3, "1500"), m.add(15, ""), _drive(m, 0.5, 0.5, robot), m.add(3, '"fwd"')]
    bump += [m.add(1, "mode")]
    m.chain(*bump)
    return b.write(path, compress=viple3, bom=not viple3)


def _drive(m, left: float, right: float, robot: str = ROBOT) -> int:
    return m.add(20, str(left), str(right), robot, "3", "5")


def runaway(path: Path) -> str:
    """A counter that counts for ever, as fast as it is let: it never gets anywhere."""
    b = ProgramBuilder()
    m = b.panel("Main")
    b.robot(m)
    start, merge, count = m.add(3, "0"), m.add(5), m.add(2, "value + 1")
    m.chain(start, merge, count, merge)
    return b.write(path)


def memory_hog(path: Path) -> str:
    """A Join that nests its own output with a new 64 KB text each time round, for ever:
    every message it makes holds all the earlier ones."""
    b = ProgramBuilder()
    m = b.panel("Main")
    b.robot(m)
    first, text = m.add(3, "0"), m.add(3, '"x"')
    doubled = [m.add(2, "value + value") for _ in range(16)]
    m.chain(text, *doubled)
    older, newer = m.add(5), m.add(5)
    join = m.add(4, "a", "b")
    grow = m.add(2, 'b + "y"')
    b.link(first, older)
    b.link(doubled[-1], newer)
    b.link(older, join, in_pin=0)
    b.link(newer, join, in_pin=1)
    b.link(join, older)
    m.chain(join, grow, newer)
    return b.write(path)
