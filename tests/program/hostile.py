"""Hostile VIPLE programs, each a few activities, for the tests and ``bench/hostile_programs.py``.

Each function returns the program's XML text, in the layout VIPLE 4.x saves. They are what a
student could bring to a lab server on purpose: loops without a wait, messages that grow
without end, numbers past every range, and files made to be slow to check.
"""

from __future__ import annotations

from tests.program.builder import ProgramBuilder

JOIN, MERGE, DATA, CALC, VARIABLE, PRINT = 4, 5, 3, 2, 1, 28
WHILE, END_WHILE, COMMENT = 8, 10, 11


def join_nesting() -> str:
    """A Join whose message goes back into it: each pass wraps the last message once more."""
    b = ProgramBuilder()
    main = b.panel("Main")
    start = main.add(DATA, "1")
    merge = main.add(MERGE)
    one = main.add(CALC, "1")
    join = main.add(JOIN, "inner", "one")
    b.link(start, merge)
    b.link(merge, join, in_pin=0)
    b.link(merge, one)
    b.link(one, join, in_pin=1)
    b.link(join, merge)
    return b.xml()


def join_doubling(printed: bool = True) -> str:
    """A Join fed twice from one Merge, its message printed each pass: the message holds the
    last one twice, so written out it doubles every pass."""
    b = ProgramBuilder()
    main = b.panel("Main")
    start = main.add(DATA, "1")
    merge = main.add(MERGE)
    join = main.add(JOIN, "left", "right")
    b.link(start, merge)
    b.link(merge, join, in_pin=0)
    b.link(merge, join, in_pin=1)
    if printed:
        show = main.add(PRINT, "")
        b.link(join, show)
        b.link(show, merge)
    else:
        b.link(join, merge)
    return b.xml()


def number_doubling() -> str:
    """``state.n + state.n`` stored back in ``n``, in a loop without a wait."""
    b = ProgramBuilder()
    b.var("n", "System.Int32")
    main = b.panel("Main")
    start = main.add(DATA, "1")
    store = main.add(VARIABLE, "n")
    merge = main.add(MERGE)
    double = main.add(CALC, "state.n + state.n")
    again = main.add(VARIABLE, "n")
    b.link(start, store)
    b.link(store, merge)
    b.link(merge, double)
    b.link(double, again)
    b.link(again, merge)
    return b.xml()


def record_flood(variables: int = 12, length: int = 90_000) -> str:
    """Text variables of ``length`` characters each, kept by the program (a run record holds
    every variable at every control tick)."""
    b = ProgramBuilder()
    main = b.panel("Main")
    text = main.add(DATA, '"' + "x" * (length // 10) + '"')
    previous = main.add(CALC, " + ".join(["value"] * 10))
    b.link(text, previous)
    for k in range(variables):
        b.var(f"s{k}", "System.String")
        store = main.add(VARIABLE, f"s{k}")
        b.link(previous, store)
        previous = store
    return b.xml()


def merge_spin() -> str:
    """A Merge feeding itself through a Calculate: a loop that never waits."""
    b = ProgramBuilder()
    main = b.panel("Main")
    start = main.add(DATA, "0")
    merge = main.add(MERGE)
    step = main.add(CALC, "value + 1")
    b.link(start, merge)
    b.link(merge, step)
    b.link(step, merge)
    return b.xml()


def long_robot_name(digits: int = 60_000) -> str:
    """Two robots, and a sensor naming its robot with a name of ``digits`` digits then a
    letter (a name made to be slow to match)."""
    b = ProgramBuilder()
    main = b.panel("Main")
    b.robot(main)
    b.robot(main)
    sensor = main.add(23, "1" * digits + "x", "1")
    show = main.add(PRINT, "")
    b.link(sensor, show)
    return b.xml()


def long_comment(length: int = 190_000) -> str:
    """A Comment whose body is ``length`` characters on one line."""
    b = ProgramBuilder()
    main = b.panel("Main")
    main.add(COMMENT, "a" * length)
    main.add(DATA, "1")
    return b.xml()


def while_lattice(width: int = 60, rows: int = 45) -> str:
    """Whiles in a grid, each leading to the two below it, and End Whiles at the bottom:
    every While's body reaches a large share of the others."""
    b = ProgramBuilder()
    main = b.panel("Main")
    start = main.add(DATA, "1")
    grid = [[main.add(WHILE, "true") for _ in range(width)] for _ in range(rows)]
    for col in range(width):
        b.link(start, grid[0][col])
    for row in range(rows - 1):
        for col in range(width):
            b.link(grid[row][col], grid[row + 1][col])
            b.link(grid[row][col], grid[row + 1][(col + 1) % width])
    for col in range(width):
        end = main.add(END_WHILE)
        b.link(grid[-1][col], end)
    return b.xml()


def many_whiles(count: int = 2_000) -> str:
    """``count`` While loops one after the other."""
    b = ProgramBuilder()
    main = b.panel("Main")
    previous = main.add(DATA, "0")
    for _ in range(count):
        loop = main.add(WHILE, "value < 1")
        end = main.add(END_WHILE)
        b.link(previous, loop)
        b.link(loop, end)
        previous = end
    return b.xml()


def many_attributes(count: int = 340_000) -> str:
    """One element with ``count`` attributes, one a line."""
    attributes = "\n".join(f"a{k}=''" for k in range(count))
    return f'<?xml version="1.0"?>\n<Program {attributes}><Version>4.0</Version></Program>\n'


def many_elements(count: int = 399_000) -> str:
    """A program of ``count`` empty elements, one a line."""
    body = "<x/>\n" * count
    return f'<?xml version="1.0"?>\n<Program><Version>4.0</Version>\n{body}</Program>\n'
