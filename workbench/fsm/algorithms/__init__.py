"""The course's maze algorithms, each an FSM file in this folder (the same YAML format students
write, run by the same engine)."""

from __future__ import annotations

import difflib
import os
from collections.abc import Callable
from functools import cache
from pathlib import Path

from workbench.files.yamlread import file_problem
from workbench.fsm.machine import FsmDefinition
from workbench.fsm.yaml_file import FsmFileError, load_fsm

ALGORITHM_DIR = Path(__file__).resolve().parent

#: the order the course meets them in; any other file here is listed after these
COURSE_ORDER = (
    "right-wall",
    "farthest-distance",
    "one-distance-first",
    "first-working-solution",
    "two-distance-local-best",
    "self-adjusting-wall",
    "web-wall-following",
    "web-two-distance",
)


def list_algorithms() -> list[str]:
    """Names of the built-in algorithms, in course order."""
    present = {p.stem for p in ALGORITHM_DIR.glob("*.yaml")}
    ordered = [name for name in COURSE_ORDER if name in present]
    return ordered + sorted(present - set(COURSE_ORDER))


def load_algorithm(
    name_or_path: str | os.PathLike[str], resolve: Callable[[str], Path] = Path
) -> FsmDefinition:
    """A built-in algorithm by name, or an FSM file by path; raises :class:`FsmFileError`.

    ``resolve`` turns what was typed into the file's path (and may refuse it).
    """
    text = str(name_or_path)
    if text in list_algorithms():
        return _builtin(text)
    path = resolve(text)
    if path.suffix in (".yaml", ".yml") or path.exists() or "/" in text or "\\" in text:
        return load_fsm(path)
    close = difflib.get_close_matches(text, list_algorithms(), n=1)
    hint = f"did you mean {close[0]!r}? " if close else ""
    raise FsmFileError(
        [
            file_problem(
                text,
                0,
                0,
                f"no built-in algorithm or FSM file named {text!r}",
                f"{hint}built-ins: {', '.join(list_algorithms())}; or give a path to a .yaml file",
            )
        ]
    )


@cache
def _builtin(name: str) -> FsmDefinition:
    return load_fsm(ALGORITHM_DIR / f"{name}.yaml")
