"""Which example VIPLE program that comes with the workbench a program is, block for block.

The example programs (``programs/*.viple``) are there to be run with ``viple run`` and read in
the docs; they solve lab exercises, so a lab must not take one as a student's own program.
Two programs are the same here when their diagrams are: the same panels with the same inputs,
the same blocks (kind, name and values) joined by the same links, and the same global
variables. What the file keeps beside that (the numbers VIPLE gave the blocks and links, where
each block is drawn, the sizes of the panels, Comment blocks, the address a Robot block names
for VIPLE's own connection, the VIPLE version that saved it, whitespace) is set aside.

Block numbers are set aside by naming each block by what it is and what it is joined to, in
two rounds (its own kind, panel, name and values; then those of the blocks on each of its
links, with the pins), so a copy whose blocks were numbered afresh, as VIPLE does when blocks
are pasted into a new diagram, is still the example it copies.
"""

from __future__ import annotations

from functools import cache
from pathlib import Path

from workbench.files.bundled import PROGRAM_DIR

from . import kinds as K
from .loader import load_program
from .model import Program
from .problems import ProgramError


def shape(program: Program) -> str:
    """A program's diagrams, without what does not change how it runs."""
    own = {
        aid: repr((a.kind, a.panel, a.name, () if a.kind == K.ROBOT else a.values))
        for aid, a in program.activities.items()
        if a.kind != K.COMMENT
    }
    links = [link for link in program.links if link.source in own and link.target in own]
    joined: dict[int, list[tuple[str, int, int, str]]] = {aid: [] for aid in own}
    for link in links:
        joined[link.source].append(("out", link.pin, link.in_pin, own[link.target]))
        joined[link.target].append(("in", link.pin, link.in_pin, own[link.source]))
    named = {aid: repr((own[aid], sorted(joined[aid]))) for aid in own}
    panels = sorted(
        (p.name, tuple(p.inputs), sorted(named[a] for a in p.activities if a in named))
        for p in program.panels.values()
    )
    edges = sorted(
        (named[link.source], link.pin, named[link.target], link.in_pin) for link in links
    )
    variables = sorted((v.name, v.type) for v in program.globals)
    return repr((panels, edges, variables))


@cache
def bundled_programs() -> tuple[tuple[str, str], ...]:
    """(how a reason names it, its shape) for every example program, read once."""
    found = []
    for path in sorted(Path(PROGRAM_DIR).glob("*.viple")):
        try:
            program = load_program(path)
        except ProgramError:
            continue
        found.append((f"the example program {path.parent.name}/{path.name}", shape(program)))
    return tuple(found)


def bundled_program(program: Program) -> str:
    """Which example program ``program`` is ("the example program programs/right-wall.viple");
    "" when it is none of them."""
    mine = shape(program)
    return next((shown for shown, theirs in bundled_programs() if theirs == mine), "")
