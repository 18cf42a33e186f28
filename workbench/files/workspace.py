"""Which files the app may open: anything on a person's own machine, and for a served student
only their own workspace folder and the bundled read-only assets.

A path the student types is turned into an absolute one first (``~`` and relative paths mean
the workspace; symlinks and ``..`` are resolved), and only then checked, so no spelling of a
path reaches past the wall. A refusal says where the student's files are and never shows
anything read from the file it refused.
"""

from __future__ import annotations

import os
import re
from dataclasses import dataclass, field
from pathlib import Path

import workbench

from .atomic import write_bytes_atomic
from .bundled import MAZE_DIR
from .reserved import reserved_problem
from .workspace_files import UploadLimits, WorkspaceError, WorkspaceFiles

_PACKAGE = Path(workbench.__file__).resolve().parent
#: the bundled mazes, labs and starter algorithms: readable by everyone, written by nobody
BUNDLED = (
    MAZE_DIR,
    _PACKAGE.parent / "labs",
    _PACKAGE / "fsm" / "algorithms",
)
#: a login name as a folder name: what the users file allows, nothing that walks
_FOLDER_NAME = re.compile(r"[A-Za-z0-9_][A-Za-z0-9_.-]{0,63}")


class OutsideWorkspace(ValueError):
    """A path the app may not open (for this student, or at all); the message says why."""


class NoRoom(OutsideWorkspace):
    """A file the workspace has no room for (its quota, file count or file cap)."""


#: how a served student frees room in their workspace, for the app's refusals
FREE_ROOM = (
    "save over one of your files instead, or remove files you no longer need "
    "(sftp, then rm NAME) and save again"
)


@dataclass(frozen=True)
class FileAccess:
    """What the app may read and write.

    Without a ``workspace`` (a person running the workbench on their own machine) every path
    is taken as typed. With one, paths are read inside the workspace or the ``bundled`` folders
    and written inside the workspace only.
    """

    workspace: Path | None = None
    bundled: tuple[Path, ...] = BUNDLED
    #: the workspace's quota, file count and file cap, as the file server keeps them (None:
    #: none); every file the app saves in the workspace is counted against it
    quota: WorkspaceFiles | None = field(default=None, compare=False, repr=False)

    @classmethod
    def confined_to(
        cls, workspace: str | os.PathLike, limits: UploadLimits | None = None
    ) -> FileAccess:
        """Access for a served student, creating the workspace folder (mode 0700) if needed;
        with ``limits``, what the app saves there is held to them."""
        root = Path(workspace)
        root.mkdir(parents=True, exist_ok=True, mode=0o700)
        root.chmod(0o700)
        quota = WorkspaceFiles(root, limits, shared=True) if limits is not None else None
        return cls(root.resolve(), tuple(p.resolve() for p in BUNDLED), quota)

    @property
    def confined(self) -> bool:
        return self.workspace is not None

    # -- resolving ---------------------------------------------------------------------------
    def resolve(self, typed: str | os.PathLike) -> Path:
        """The absolute path ``typed`` means (not checked, but never with control characters)."""
        text = os.fspath(typed).strip()
        if not text.isprintable():
            raise OutsideWorkspace(
                "a path cannot hold control characters: type the path again, without them"
            )
        if self.workspace is None:
            return Path(text).expanduser()
        if text == "~" or text.startswith("~/"):
            text = text[2:]
        elif text.startswith("~"):
            raise OutsideWorkspace(f"{text.split('/')[0]!r} is another user's home: {self.where()}")
        path = Path(text)
        if not path.is_absolute():
            path = self.workspace / path
        return path.resolve()

    def for_reading(self, typed: str | os.PathLike) -> Path:
        """The path to read ``typed`` from; :class:`OutsideWorkspace` when it may not be read."""
        path = self.resolve(typed)
        if self.workspace is None or self._inside(path, (self.workspace, *self.bundled)):
            return path
        raise OutsideWorkspace(f"{self.shown(typed)} is outside your workspace: {self.where()}")

    def for_writing(self, typed: str | os.PathLike) -> Path:
        """The path to write ``typed`` to; :class:`OutsideWorkspace` when it may not be written.

        The bundled mazes, labs and starters are never written, whoever runs the app.
        """
        path = self.resolve(typed)
        if self._inside(path.resolve(), self.bundled):
            raise OutsideWorkspace(
                f"{self.shown(typed)} is a bundled file, kept as shipped for everyone: save your "
                f"own copy under another name{self._in_workspace()}"
            )
        if self.workspace is None:
            return path
        if self._inside(path, (self.workspace,)):
            problem = reserved_problem(path.relative_to(self.workspace).parts)
            if problem:
                raise OutsideWorkspace(f"{self.shown(path)} {problem}")
            return path
        raise OutsideWorkspace(
            f"{self.shown(typed)} is outside your workspace: you can save only in your "
            f"workspace, {self.shown(self.workspace)}"
        )

    def write_bytes(self, typed: str | os.PathLike, data: bytes) -> Path:
        """Save ``data`` whole at ``typed`` (:func:`~.atomic.write_bytes_atomic`), within the
        write rules of :meth:`for_writing` and the workspace's quota; :class:`OutsideWorkspace`
        (:class:`NoRoom` for the quota) when it may not be. The path written is returned."""
        path = self.for_writing(typed)
        if self.quota is not None and self.workspace is not None:
            parts = path.relative_to(self.workspace).parts
            try:
                self.quota.room_for(parts, len(data), self.shown(path), FREE_ROOM)
            except WorkspaceError as exc:
                raise NoRoom(exc.message) from None
        write_bytes_atomic(path, data)
        return path

    def allows_writing(self, path: str | os.PathLike) -> bool:
        try:
            self.for_writing(path)
        except OutsideWorkspace:
            return False
        return True

    # -- telling the student -----------------------------------------------------------------
    def home(self) -> str:
        """Where a file dialog starts: ``~/`` in a workspace, else the current folder."""
        return "~/" if self.workspace is not None else ""

    def shown(self, path: str | os.PathLike) -> str:
        """A path as the student sees it: ``~/...`` inside the workspace."""
        text = os.fspath(path).strip()
        if self.workspace is None:
            return text
        try:
            resolved = self.resolve(text)
        except OutsideWorkspace:
            return text[:200]
        if self._inside(resolved, (self.workspace,)):
            inner = resolved.relative_to(self.workspace).as_posix()
            return "~/" if inner == "." else f"~/{inner}"
        return text[:200]

    def note(self) -> str:
        """A line for file dialogs: where the student's files are (empty when not confined)."""
        if self.workspace is None:
            return ""
        return (
            "On this server your files are in your workspace, ~/ (a path without / is there "
            "too); the bundled mazes, labs and starters can be opened, not changed."
        )

    def where(self) -> str:
        """What a confined student may open, for refusals and dialog hints."""
        bundled = ", ".join(str(p) + "/" for p in self.bundled)
        return f"you can open files in your workspace (~/) and the bundled files in {bundled}"

    def _in_workspace(self) -> str:
        return ", e.g. in ~/" if self.workspace is not None else ""

    @staticmethod
    def _inside(path: Path, folders: tuple[Path, ...]) -> bool:
        return any(path == folder or path.is_relative_to(folder) for folder in folders)


def workspace_folder(data_dir: str | os.PathLike, user: str) -> Path:
    """``<data-dir>/workspaces/<user>``: a served student's own folder."""
    if not _FOLDER_NAME.fullmatch(user) or user in {".", ".."}:
        raise ValueError(f"{user!r} cannot name a workspace folder")
    return workspaces_folder(data_dir) / user


def workspaces_folder(data_dir: str | os.PathLike) -> Path:
    """``<data-dir>/workspaces``: every served student's folder is in it."""
    return Path(data_dir) / "workspaces"


LOCAL = FileAccess()
