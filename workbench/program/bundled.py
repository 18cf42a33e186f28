"""Which example VIPLE program that comes with the workbench a program is, block for block.

The example programs (``programs/*.viple``) are there to be run with ``viple run`` and read in
the docs; they solve lab exercises, so a lab must not take one as a student's own program.
Two programs are the same here when their diagrams are: the same panels with the same inputs,
the same blocks (kind, name and values) under the same ids, the same links and the same
global variables. What the file keeps beside that (where each block is drawn, the sizes of
the panels, Comment blocks, the address a Robot block names for VIPLE's own connection, the
VIPLE version that saved it, whitespace) is set aside.
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
    kept = {
        aid: (a.kind, a.panel, a.name, () if a.kind == K.ROBOT else a.values)
        for aid, a in program.activities.items()
        if a.kind != K.COMMENT
    }
    panels = sorted(
        (p.name, tuple(p.inputs), tuple(sorted(a for a in p.activities if a in kept)))
        for p in program.panels.values()
    )
    links = sorted((link.source, link.pin, link.target, link.in_pin) for link in program.links)
    variables = sorted((v.name, v.type) for v in program.globals)
    return repr((panels, sorted(kept.items()), links, variables))


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
