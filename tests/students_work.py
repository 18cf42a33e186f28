"""Work a student could hand in, for the lab tests: programs that are their own, made from
the examples that come with the workbench (which are not)."""

from __future__ import annotations

import re
from pathlib import Path

EXAMPLES = Path(__file__).resolve().parents[1] / "programs"


def own_right_wall(folder: Path, name: str = "my-right-wall.viple") -> Path:
    """The example right-wall follower with its 450 ms timer made 440 ms: a program of the
    student's own (it still gets out of the Web maze, in about 71 s)."""
    text = (EXAMPLES / "right-wall.viple").read_text(encoding="utf-8-sig")
    assert text.count("<Value>450</Value>") == 1
    path = folder / name
    path.write_text(text.replace("<Value>450</Value>", "<Value>440</Value>"), encoding="utf-8")
    return path


def example_copy(folder: Path, example: str, name: str) -> Path:
    """An example program copied under another name, with its blocks moved on the diagram and
    its comment rewritten: still the example, block for block."""
    text = (EXAMPLES / example).read_text(encoding="utf-8-sig")
    text = text.replace("<Left>10</Left>", "<Left>240</Left>")
    text = text.replace("Right-wall follower", "My own wall follower")
    path = folder / name
    path.write_text(text, encoding="utf-8")
    return path


def example_renumbered(folder: Path, example: str, name: str) -> Path:
    """An example program whose blocks and links are all numbered afresh (as pasting them into
    a new diagram numbers them), listed in another order: still the example, block for block."""
    text = (EXAMPLES / example).read_text(encoding="utf-8-sig")
    text = re.sub(
        r"<ActivityID>(\d+)</ActivityID>",
        lambda found: f"<ActivityID>{1000 - int(found[1])}</ActivityID>",
        text,
    )
    text = re.sub(
        r"<GraphEdgeID>(\d+)</GraphEdgeID>",
        lambda found: f"<GraphEdgeID>{700 + 3 * int(found[1])}</GraphEdgeID>",
        text,
    )
    path = folder / name
    path.write_text(text, encoding="utf-8")
    return path
