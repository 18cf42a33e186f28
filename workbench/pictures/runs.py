"""The runs a picture is drawn from: run records read and checked, each with its maze.

A record is refused before it is read when it is not a plain file or larger than any record
the workbench writes (its cap, :data:`MAX_RECORD`); then it is read as a replay reads it
(``sim/replay.py``: every tick line checked), and its maze found as the replay finds it. Every
refusal is a :class:`PictureError` naming the file and what to do instead.
"""

from __future__ import annotations

import os
import stat
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

from workbench.control.recording import RECORD_CAP
from workbench.files.bundled import maze_path
from workbench.files.terminal import terminal_safe
from workbench.files.workspace import LOCAL, FileAccess, OutsideWorkspace
from workbench.sim.maze import Maze, MazeError
from workbench.sim.mazeio import load_maze
from workbench.sim.profiles import PROFILES, Profile
from workbench.sim.record import SUMMARY_ROOM, RecordError
from workbench.sim.replay import Replay, load_replay, replay_maze

#: the largest record a picture is drawn from: the cap a record is written under, and room for
#: its summary line
MAX_RECORD = RECORD_CAP + SUMMARY_ROOM
#: the most runs one picture puts side by side
MAX_RUNS = 12
#: how far (in blocks) a recorded pose may lie outside its maze before the record is refused
MARGIN_BLOCKS = 2.0


#: what to do when a record's maze is not found, on the command line
MAZE_HINT = "give the run's maze file with --maze FILE"


class PictureError(ValueError):
    """A picture that cannot be drawn or saved; the message names the file and the fix."""


@dataclass(frozen=True)
class PictureRun:
    """One run to draw: its record (as a replay), the file it came from, its maze and profile."""

    path: Path
    replay: Replay
    maze: Maze
    profile: Profile
    #: what the student should know about the maze (its file changed since the run), or ""
    note: str = ""
    #: how the caption names the record ("" : ``record NAME``)
    record_words: str = ""

    @property
    def name(self) -> str:
        """The record's file name, as the picture names the run."""
        return self.path.name

    @property
    def cell(self) -> float:
        return self.replay.cell


def _check_file(path: Path, shown: str) -> None:
    try:
        info = os.stat(path)
    except FileNotFoundError:
        raise PictureError(
            f"{shown}: no such file: give the path of a run record (.jsonl)"
        ) from None
    except OSError as exc:
        raise PictureError(f"{shown}: cannot read it ({exc.strerror}): check the path") from None
    if not stat.S_ISREG(info.st_mode):
        raise PictureError(f"{shown}: not a plain file: give the path of a run record (.jsonl)")
    if info.st_size > MAX_RECORD:
        raise PictureError(
            f"{shown}: {info.st_size:,} bytes is larger than any run record the workbench "
            f"writes ({MAX_RECORD:,} bytes): draw a record of a shorter run"
        )


def _pose_problem(replay: Replay, maze: Maze) -> str:
    cell = replay.cell
    margin = MARGIN_BLOCKS * cell
    low_x, low_y = -margin, -margin
    high_x, high_y = maze.width * cell + margin, maze.height * cell + margin
    for i, pose in enumerate(replay.poses):
        if not (low_x <= pose.x <= high_x and low_y <= pose.y <= high_y):
            return (
                f"tick {i + 1} puts the robot at ({pose.x:g}, {pose.y:g}), outside the maze "
                f"{terminal_safe(maze.name or '-')}: the record belongs to another maze or was "
                "changed after it was written"
            )
    return ""


def load_run(
    typed: str | os.PathLike,
    maze: Maze | None = None,
    files: FileAccess = LOCAL,
    known: Sequence[Maze] = (),
    maze_hint: str = MAZE_HINT,
) -> PictureRun:
    """Read the record at ``typed`` and find its maze; with ``maze``, the record must be a run
    on that maze (its layout digest). :class:`PictureError` says why a record cannot be drawn."""
    shown = terminal_safe(files.shown(typed))
    try:
        path = files.for_reading(typed)
    except OutsideWorkspace as exc:
        raise PictureError(str(exc)) from None
    _check_file(path, shown)
    try:
        replay = load_replay(path)
    except RecordError as exc:
        raise PictureError(f"{terminal_safe(str(exc))}: draw another record") from None
    except (OSError, ValueError) as exc:  # (a file that changed under us)
        raise PictureError(f"{shown}: cannot read it as a run record ({exc})") from None
    info = replay.header.get("maze")
    digest = info.get("digest") if isinstance(info, dict) else None
    if maze is not None:
        if digest != maze.digest():
            recorded = info.get("name") if isinstance(info, dict) else None
            raise PictureError(
                f"{shown}: a run on {terminal_safe(str(recorded or 'another maze'))}, not on "
                f"{terminal_safe(maze.name or 'the maze given')}: give that run's own maze, "
                "or leave the maze out to use the one the record names"
            )
        found, note = maze, ""
    else:
        found_or_none, note = replay_maze(replay, path, known, files)
        if found_or_none is None:
            raise PictureError(f"{shown}: {note}: {maze_hint}")
        found = found_or_none
    profile = PROFILES.get(str(replay.header.get("profile")))
    if profile is None:
        raise PictureError(
            f"{shown}: the header names no profile the workbench knows "
            f"({', '.join(PROFILES)}): the record was changed after it was written"
        )
    problem = _pose_problem(replay, found)
    if problem:
        raise PictureError(f"{shown}: {problem}")
    return PictureRun(path, replay, found, profile, note)


def read_maze(typed: str, files: FileAccess = LOCAL) -> Maze:
    """The maze file ``typed`` names (a path, or a bundled maze by name), for ``--maze``."""
    try:
        path = files.for_reading(maze_path(typed))
        return load_maze(path)
    except OutsideWorkspace as exc:
        raise PictureError(str(exc)) from None
    except MazeError as exc:
        first = exc.problems[0] if exc.problems else "it cannot be read"
        raise PictureError(f"{terminal_safe(typed)}: not a maze ({first}): check --maze") from None
    except OSError as exc:
        raise PictureError(
            f"{terminal_safe(typed)}: cannot read the maze ({exc.strerror}): check --maze"
        ) from None


def load_runs(
    paths: Sequence[str | os.PathLike],
    maze: Maze | None = None,
    files: FileAccess = LOCAL,
    known: Sequence[Maze] = (),
    maze_hint: str = MAZE_HINT,
) -> list[PictureRun]:
    """The runs of one picture, all on one maze: runs on different mazes are refused."""
    if not paths:
        raise PictureError("no run record given: name at least one .jsonl file")
    if len(paths) > MAX_RUNS:
        raise PictureError(
            f"{len(paths)} records is more than one picture holds ({MAX_RUNS}): draw them in groups"
        )
    runs = [load_run(p, maze, files, known, maze_hint) for p in paths]
    first = runs[0]
    for run in runs[1:]:
        if run.maze.digest() != first.maze.digest():
            raise PictureError(
                f"{run.name} is a run on {terminal_safe(run.maze.name or 'another maze')} and "
                f"{first.name} on {terminal_safe(first.maze.name or 'another maze')}: runs "
                "side by side must share one maze, so draw each maze's runs in a picture of "
                "their own"
            )
    return runs
