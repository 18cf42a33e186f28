"""Saving a picture where the app keeps them: the workspace's ``pictures/`` folder.

Names come from ``naming.py`` and go through the workspace's rules (``files/workspace.py``):
on the lab server a name never leaves the student's workspace and the file counts against its
quota, so the student downloads it with ``sftp`` or ``scp``; on a person's own machine the
folder is ``pictures/`` in the current folder.
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

from workbench.files.workspace import FileAccess, OutsideWorkspace
from workbench.sim.maze import Maze

from .naming import app_compare_name, app_picture_name
from .render import PictureSpec, save_picture
from .runs import PictureError, load_runs

#: what to do in the app when a record's maze is not found
APP_MAZE_HINT = "load that maze on the workbench (m) and save the picture again"


@dataclass(frozen=True)
class SavedPicture:
    """A picture the app saved: where, as the student sees it, its size, kind and runs."""

    path: Path
    shown: str
    size: int
    kind: str
    runs: int


def save_in_workspace(
    records: Sequence[str | os.PathLike],
    kind: str,
    files: FileAccess,
    *,
    at: Sequence[float] = (),
    known: Sequence[Maze] = (),
) -> SavedPicture:
    """Draw ``records`` as a ``kind`` picture into ``pictures/`` (made when missing) and say
    where it went; :class:`PictureError` says why it could not be drawn or saved."""
    runs = load_runs(records, files=files, known=known, maze_hint=APP_MAZE_HINT)
    if kind == "compare":
        name = app_compare_name(runs[0].maze.name or Path(runs[0].maze.source).stem, len(runs))
    else:
        name = app_picture_name(runs[0].path, kind)
    try:
        folder = files.for_writing(name).parent
        folder.mkdir(mode=0o700, exist_ok=True)
    except OutsideWorkspace as exc:
        raise PictureError(str(exc)) from None
    except OSError as exc:
        raise PictureError(
            f"{files.shown(folder)}: cannot make the pictures folder ({exc.strerror})"
        ) from None
    path = save_picture(runs, name, PictureSpec(kind, at=tuple(at)), files)
    return SavedPicture(path, files.shown(path), path.stat().st_size, kind, len(runs))
