"""The FSM editor's file: opening a student's FSM, checking its text, saving it.

The text itself is the editor widget's (with its undo history); this module holds what is
not: where the file is, the text as last saved, and the rules it is read and written by. A
file is read through the station's :class:`~workbench.files.workspace.FileAccess` and the
bounded reader's FSM limits, and saved whole with the atomic writer, within the workspace's
rules and quota, exactly as the maze editor saves a maze. A text past the FSM limits is not
saved (the file would not load).
"""

from __future__ import annotations

import os
from dataclasses import dataclass, field
from pathlib import Path

from workbench.files.bounded import FSM_LIMITS, BoundedFileError, check_text, read_text
from workbench.files.problems import Problem
from workbench.files.workspace import FileAccess, OutsideWorkspace
from workbench.files.yamlread import file_problem, refused_problem

from .machine import FsmDefinition
from .yaml_file import FsmFileError, loads_fsm

#: the file name a new FSM is offered under
NEW_NAME = "my-fsm.yaml"


class FsmEditError(ValueError):
    """A file that cannot be opened or saved; the message says why and what to do."""


@dataclass(frozen=True)
class Checked:
    """What the FSM loader makes of a text: the definition, or every problem with its place
    (line and column from 1)."""

    definition: FsmDefinition | None
    problems: tuple[Problem, ...] = ()


def check(text: str, filename: str = NEW_NAME) -> Checked:
    """``text`` read as an FSM file (the FSM limits hold: a text past them is one problem)."""
    size = len(text.encode("utf-8", "surrogatepass"))
    if size > FSM_LIMITS.max_bytes:
        problem = file_problem(
            filename, 1, 1, f"the text is {size:,} bytes, over the {FSM_LIMITS.max_bytes:,} "
            "bytes an FSM file may hold", "keep the machine smaller",
        )  # fmt: skip
        return Checked(None, (problem,))
    try:
        return Checked(loads_fsm(text, filename))
    except FsmFileError as exc:
        return Checked(None, tuple(exc.problems))


@dataclass
class FsmDraft:
    """The file being edited: its path ("" until saved) and the text as last saved."""

    files: FileAccess
    path: str = ""
    saved: str = ""
    #: the files written, as the student sees them, oldest first
    written: list[str] = field(default_factory=list)

    @classmethod
    def open(cls, files: FileAccess, typed: str) -> FsmDraft:
        """The FSM file at ``typed`` (a new, empty one when there is none yet); an
        :class:`FsmEditError` when it may not be read or is not text within the limits."""
        try:
            path = files.for_reading(typed)
        except OutsideWorkspace as exc:
            raise FsmEditError(str(exc)) from None
        if not path.exists():
            return cls(files, str(path), "")
        try:
            text = read_text(path, FSM_LIMITS, files.shown(path))
        except BoundedFileError as exc:
            raise FsmEditError(str(refused_problem(exc))) from None
        except OSError as exc:
            raise FsmEditError(f"{files.shown(path)}: cannot be read: {exc.strerror}") from None
        return cls(files, str(path), text)

    @property
    def shown(self) -> str:
        return self.files.shown(self.path) if self.path else "not saved yet"

    def dirty(self, text: str) -> bool:
        return text != self.saved

    def suggested(self) -> str:
        if self.path:
            return self.files.shown(self.path)
        return self.files.home() + NEW_NAME

    def save(self, text: str, typed: str | os.PathLike | None = None) -> Path:
        """Write ``text`` to ``typed`` (None: where it was opened or last saved); an
        :class:`FsmEditError` when it may not be written there or is past the FSM limits."""
        target = typed if typed is not None else self.path
        if not target:
            raise FsmEditError("choose a file name to save to")
        name = self.files.shown(target)
        try:
            check_text(text, name, FSM_LIMITS)
        except BoundedFileError as exc:
            raise FsmEditError(f"not saved: {refused_problem(exc)}") from None
        data = text.encode("utf-8")
        if len(data) > FSM_LIMITS.max_bytes:
            raise FsmEditError(
                f"not saved: {name} would be {len(data):,} bytes, over the "
                f"{FSM_LIMITS.max_bytes:,} bytes an FSM file may hold"
            )
        if not str(target).endswith((".yaml", ".yml")):
            raise FsmEditError(f"{name}: an FSM file's name ends in .yaml: add it")
        try:
            path = self.files.write_bytes(target, data)
        except OutsideWorkspace as exc:
            raise FsmEditError(str(exc)) from None
        except OSError as exc:
            raise FsmEditError(f"{name}: cannot be written: {exc.strerror}") from None
        self.path = str(path)
        self.saved = text
        self.written.append(self.files.shown(path))
        return path
