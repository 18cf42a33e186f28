"""Bidirectional text controls: invisible characters that make text show in another order
than it is stored (U+202E turns ``txt.exe`` into what reads as ``exe.txt``). Names people
read (mazes, maze files, students) must not hold them."""

from __future__ import annotations

import re

#: the embeddings and overrides, the isolates, the left-to-right and right-to-left marks and
#: the Arabic letter mark
BIDI_CONTROLS = re.compile("[\u202a-\u202e\u2066-\u2069\u200e\u200f\u061c]")


def bidi_problem(text: str, what: str) -> str:
    """Why ``text`` cannot be used (naming the first bidi control and its position), or
    ``""`` when it holds none; ``what`` names the text (e.g. "the maze's name")."""
    found = BIDI_CONTROLS.search(text)
    if found is None:
        return ""
    return (
        f"{what} has a bidi control character (U+{ord(found.group()):04X} at position "
        f"{found.start() + 1}), which shows text in another order than it is written"
    )
