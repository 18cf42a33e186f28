"""A workspace as a file server sees it: the operations on a student's files from outside the
app (listing, reading, uploading, removing, renaming, folders), each confined to the workspace,
and the room the student's own files take counted against a quota.

:class:`WorkspaceFiles` keeps the files in the workspace folder on disk. Every path is given
as its parts inside the workspace (checked by :mod:`workbench.files.names`), and every change
is told to ``on_change`` with the path it changed, relative to the workspace (``"a/b.viple"``),
once it is made (in the thread that made it: an upload may be committed in a worker thread): a
workspace kept elsewhere as well (the course's database) syncs from there.

An upload is written whole or not at all: its bytes go to a hidden file in the workspace's
``.uploading`` folder and take the file's name only at :meth:`Upload.commit`; an upload
abandoned (a client gone mid-way) leaves nothing, and the room it held is free again. The
room an upload may take is reserved as it grows, against one count per workspace, so uploads
racing on several connections cannot pass the quota together.
"""

from __future__ import annotations

import contextlib
import errno
import os
import shutil
import stat
import threading
from collections.abc import Callable
from dataclasses import dataclass, field
from enum import Enum
from pathlib import Path
from typing import BinaryIO

from .atomic import PendingFile
from .names import UPLOADS_FOLDER, Parts, shown_path
from .reserved import RESERVED
from .sizes import shown_size

#: the largest one file may be, all of a student's files together, and how many
FILE_CAP = 5_000_000
QUOTA_BYTES = 50_000_000
QUOTA_FILES = 2000
#: how much of a file is copied at a time when an upload starts from it
_CHUNK = 1 << 20


@dataclass(frozen=True)
class UploadLimits:
    """What one student may keep in their workspace through a file server."""

    #: the largest one file may be, in bytes (0: no cap)
    file_size: int = FILE_CAP
    #: all of the student's files (run records not counted: they have their own quota)
    quota_bytes: int = QUOTA_BYTES
    #: how many files and folders (run records not counted); 0 in any of them: no limit
    quota_files: int = QUOTA_FILES


class Refusal(Enum):
    MISSING = "missing"
    EXISTS = "exists"
    DENIED = "denied"
    TOO_BIG = "too big"
    QUOTA = "quota"
    NOT_A_FOLDER = "not a folder"
    IS_A_FOLDER = "is a folder"
    NOT_EMPTY = "not empty"
    FAILED = "failed"


class WorkspaceError(Exception):
    """An operation refused, with its kind and the reason in words."""

    def __init__(self, kind: Refusal, message: str) -> None:
        super().__init__(message)
        self.kind = kind
        self.message = message


@dataclass(frozen=True)
class Entry:
    name: str
    is_folder: bool
    size: int
    mtime: float
    atime: float


@dataclass
class Usage:
    """The room a workspace's files take, and what uploads under way have reserved."""

    bytes: int = 0
    files: int = 0
    reserved_bytes: int = 0
    reserved_files: int = 0


ChangeHook = Callable[[str], None]


@dataclass
class WorkspaceFiles:
    """One workspace's files on disk (see the module's notes).

    ``read_only`` refuses every change (an instructor's view of the workspaces); the folders
    in ``protected`` (the run records the app keeps) can be read and never changed.
    ``shared`` is the quota as the app keeps it: the file server of another process may be
    uploading into the same workspace, so its uploads are left alone, and the room is
    counted afresh from the disk each time a file is saved (:meth:`room_for`).
    """

    root: Path
    limits: UploadLimits = field(default_factory=UploadLimits)
    read_only: bool = False
    protected: tuple[str, ...] = RESERVED
    on_change: ChangeHook | None = None
    shared: bool = False
    usage: Usage = field(init=False)

    def __post_init__(self) -> None:
        self.root = Path(self.root).resolve()
        self._lock = threading.Lock()
        self.usage = Usage()
        if not self.read_only:
            self.root.mkdir(parents=True, exist_ok=True, mode=0o700)
            if not self.shared:
                self.clear_uploads()
            self.usage.bytes, self.usage.files = self._count()

    # -- reading -----------------------------------------------------------------------------
    def stat(self, parts: Parts) -> Entry:
        path = self._existing(parts)
        return _entry(path.name, os.stat(path))

    def list(self, parts: Parts) -> list[Entry]:
        """The files and folders in the folder ``parts`` (links and special files left out)."""
        path = self._existing(parts)
        if not path.is_dir():
            raise WorkspaceError(Refusal.NOT_A_FOLDER, f"{shown_path(parts)} is not a folder")
        entries = []
        with os.scandir(path) as found:
            for item in found:
                if item.name == UPLOADS_FOLDER:
                    continue
                info = item.stat(follow_symlinks=False)
                if stat.S_ISREG(info.st_mode) or stat.S_ISDIR(info.st_mode):
                    entries.append(_entry(item.name, info))
        return sorted(entries, key=lambda e: e.name)

    def open_read(self, parts: Parts) -> BinaryIO:
        path = self._existing(parts)
        try:
            fd = os.open(path, os.O_RDONLY | os.O_NOFOLLOW | os.O_NONBLOCK)
        except OSError as exc:
            raise _refusal(exc, parts) from None
        if not stat.S_ISREG(os.fstat(fd).st_mode):
            os.close(fd)
            raise WorkspaceError(Refusal.IS_A_FOLDER, f"{shown_path(parts)} is not a file")
        os.set_blocking(fd, True)
        return os.fdopen(fd, "rb", buffering=0)

    # -- writing -----------------------------------------------------------------------------
    def begin_write(self, parts: Parts, *, keep: bool = False, exclusive: bool = False) -> Upload:
        """An upload to ``parts``: empty, or with the file's bytes now when ``keep``. It is
        seen under its name once committed; ``exclusive`` refuses a file that is there."""
        path = self._writable(parts)
        self._folder_of(parts)
        old = self._file_size(path, parts)
        if old is not None and exclusive:
            raise WorkspaceError(Refusal.EXISTS, f"{shown_path(parts)} is there already")
        upload = Upload(self, parts, path)
        try:
            if old is None:
                upload.reserve_file()
            elif keep:
                with open(path, "rb") as source:
                    offset = 0
                    while chunk := source.read(_CHUNK):
                        upload.write(offset, chunk)
                        offset += len(chunk)
        except BaseException:
            upload.abandon()
            raise
        return upload

    def remove(self, parts: Parts) -> None:
        path = self._writable(parts)
        size = self._file_size(path, parts)
        if size is None:
            raise WorkspaceError(Refusal.MISSING, f"{shown_path(parts)}: no such file")
        try:
            os.unlink(path)
        except OSError as exc:
            raise _refusal(exc, parts) from None
        with self._lock:
            self.usage.bytes -= size
            self.usage.files -= 1
        self._changed(parts)

    def mkdir(self, parts: Parts) -> None:
        path = self._writable(parts)
        self._folder_of(parts)
        with self._lock:
            self._check_room(0, 1, parts)
            try:
                os.mkdir(path, 0o700)
            except OSError as exc:
                raise _refusal(exc, parts) from None
            self.usage.files += 1
        self._changed(parts)

    def rmdir(self, parts: Parts) -> None:
        path = self._writable(parts)
        if not path.is_dir() or path.is_symlink():
            raise WorkspaceError(Refusal.NOT_A_FOLDER, f"{shown_path(parts)} is not a folder")
        try:
            os.rmdir(path)
        except OSError as exc:
            raise _refusal(exc, parts) from None
        with self._lock:
            self.usage.files -= 1
        self._changed(parts)

    def rename(self, old: Parts, new: Parts, *, replace: bool = False) -> None:
        """Move a file or folder within the workspace; a file at ``new`` is replaced only when
        ``replace`` (a folder never is)."""
        source, target = self._writable(old), self._writable(new)
        self._existing(old)
        self._folder_of(new)
        if new[: len(old)] == old:
            raise WorkspaceError(Refusal.DENIED, f"{shown_path(old)} cannot be moved into itself")
        replaced = None
        if os.path.lexists(target):
            replaced = self._file_size(target, new)
            if not replace or replaced is None:
                raise WorkspaceError(Refusal.EXISTS, f"{shown_path(new)} is there already")
        try:
            os.replace(source, target) if replace else os.rename(source, target)
        except OSError as exc:
            raise _refusal(exc, new) from None
        if replaced is not None:
            with self._lock:
                self.usage.bytes -= replaced
                self.usage.files -= 1
        self._changed(old)
        self._changed(new)

    def set_times(self, parts: Parts, atime: float, mtime: float) -> None:
        path = self._writable(parts)
        self._existing(parts)
        try:
            os.utime(path, (atime, mtime), follow_symlinks=False)
        except OSError as exc:
            raise _refusal(exc, parts) from None

    def clear_uploads(self) -> None:
        """Remove what abandoned uploads left (a server stopped mid-way): call it while no
        upload to this workspace is under way."""
        folder = self.root / UPLOADS_FOLDER
        if folder.is_symlink() or folder.is_file():
            folder.unlink()
        elif folder.exists():
            shutil.rmtree(folder, ignore_errors=True)

    # -- the quota ---------------------------------------------------------------------------
    def reserve(self, size: int, files: int, parts: Parts) -> None:
        with self._lock:
            self._check_room(size, files, parts)
            self.usage.reserved_bytes += size
            self.usage.reserved_files += files

    def room_for(self, parts: Parts, size: int, shown: str | None = None, free: str = "") -> None:
        """Refuse (:class:`WorkspaceError`, ``TOO_BIG`` or ``QUOTA``) a whole file of ``size``
        bytes saved at ``parts`` (replacing what is there) when it would pass the file cap,
        the quota or the file count: the check an upload makes, for a writer that writes the
        file whole itself (the app). ``shown`` is the path as that writer shows it, ``free``
        how its user frees room. A ``shared`` workspace is counted afresh from the disk."""
        where = shown or shown_path(parts)
        self._writable(parts)
        cap = self.limits.file_size
        if cap and size > cap:
            raise WorkspaceError(
                Refusal.TOO_BIG,
                f"{where}: a file may be at most {shown_size(cap)} on this server and this one "
                f"would be {shown_size(size)}",
            )
        old = self._file_size(self._path(parts), parts)
        with self._lock:
            if self.shared:
                self.usage.bytes, self.usage.files = self._count()
            self._check_room(
                max(0, size - (old or 0)), 0 if old is not None else 1, parts, where, free
            )

    def release(self, size: int, files: int) -> None:
        with self._lock:
            self.usage.reserved_bytes -= size
            self.usage.reserved_files -= files

    def _check_room(
        self, size: int, files: int, parts: Parts, shown: str | None = None, free: str = ""
    ) -> None:
        limits, usage = self.limits, self.usage
        where = shown or shown_path(parts)
        free = free or "remove some files and try again"
        if (
            limits.quota_bytes
            and size
            and (usage.bytes + usage.reserved_bytes + size > limits.quota_bytes)
        ):
            raise WorkspaceError(
                Refusal.QUOTA,
                f"{where}: your files may take at most "
                f"{shown_size(limits.quota_bytes)} on this server and take "
                f"{shown_size(usage.bytes + usage.reserved_bytes)} already: {free}",
            )
        if (
            limits.quota_files
            and files
            and (usage.files + usage.reserved_files + files > limits.quota_files)
        ):
            raise WorkspaceError(
                Refusal.QUOTA,
                f"{where}: you may keep at most {limits.quota_files} files and "
                f"folders on this server, and you have that many: {free}",
            )

    def _count(self) -> tuple[int, int]:
        """The bytes and the number of files and folders of the workspace, run records and
        uploads under way left out."""
        size = files = 0
        skip = {self.root / name for name in (*self.protected, UPLOADS_FOLDER)}
        for folder, dirs, names in os.walk(self.root):
            here = Path(folder)
            dirs[:] = [d for d in dirs if here / d not in skip]
            files += len(dirs)
            for name in names:
                with contextlib.suppress(OSError):
                    info = os.lstat(here / name)
                    if here / name not in skip:
                        files += 1
                        size += info.st_size if stat.S_ISREG(info.st_mode) else 0
        return size, files

    # -- paths -------------------------------------------------------------------------------
    def _path(self, parts: Parts) -> Path:
        """The path of ``parts`` on disk, refused when a link on the way leads anywhere."""
        path = self.root.joinpath(*parts)
        parent = path.parent if parts else path
        if os.path.realpath(parent) != str(parent) or (parts and path.is_symlink()):
            raise WorkspaceError(
                Refusal.DENIED, f"{shown_path(parts)} passes through a link, which is not followed"
            )
        return path

    def _existing(self, parts: Parts) -> Path:
        path = self._path(parts)
        try:
            info = os.lstat(path)
        except OSError as exc:
            raise _refusal(exc, parts) from None
        if not (stat.S_ISREG(info.st_mode) or stat.S_ISDIR(info.st_mode)):
            raise WorkspaceError(Refusal.DENIED, f"{shown_path(parts)} is not a file or folder")
        return path

    def _writable(self, parts: Parts) -> Path:
        if self.read_only:
            raise WorkspaceError(
                Refusal.DENIED, f"{shown_path(parts)}: the workspaces are read-only for you"
            )
        if not parts:
            raise WorkspaceError(Refusal.DENIED, "/ is your workspace itself: name a file in it")
        if parts[0] in self.protected:
            raise WorkspaceError(
                Refusal.DENIED,
                f"{shown_path(parts)}: /{parts[0]} holds the run records the workbench keeps; "
                f"they can be read and copied, not changed: use another name",
            )
        return self._path(parts)

    def _folder_of(self, parts: Parts) -> None:
        folder = self._path(parts[:-1])
        if not folder.is_dir():
            raise WorkspaceError(
                Refusal.MISSING, f"{shown_path(parts[:-1])}: no such folder (make it first)"
            )

    def _file_size(self, path: Path, parts: Parts) -> int | None:
        """The size of the file at ``path``; None when there is none; refused for a folder."""
        try:
            info = os.lstat(path)
        except FileNotFoundError:
            return None
        except OSError as exc:
            raise _refusal(exc, parts) from None
        if not stat.S_ISREG(info.st_mode):
            raise WorkspaceError(Refusal.IS_A_FOLDER, f"{shown_path(parts)} is a folder")
        return info.st_size

    def _changed(self, parts: Parts) -> None:
        if self.on_change is not None:
            self.on_change("/".join(parts))


class Upload:
    """A file being uploaded: written at any offset, read back, and seen under its name only
    once :meth:`commit` is called; the room it grows into is reserved as it grows."""

    def __init__(self, files: WorkspaceFiles, parts: Parts, target: Path) -> None:
        self.files = files
        self.parts = parts
        self.target = target
        self.reserved = 0
        self.file_slot = 0
        folder = files.root / UPLOADS_FOLDER
        folder.mkdir(mode=0o700, exist_ok=True)
        self.pending = PendingFile(folder, "upload")
        self.size = 0

    def reserve_file(self) -> None:
        self.files.reserve(0, 1, self.parts)
        self.file_slot = 1

    def write(self, offset: int, data: bytes) -> None:
        end = offset + len(data)
        self._grow(end)
        self.pending.write(offset, data)
        self.size = max(self.size, end)

    def read(self, offset: int, size: int) -> bytes:
        return self.pending.read(offset, size)

    def truncate(self, size: int) -> None:
        self._grow(size)
        self.pending.truncate(size)
        self.size = size

    def _grow(self, end: int) -> None:
        cap = self.files.limits.file_size
        if cap and end > cap:
            raise WorkspaceError(
                Refusal.TOO_BIG,
                f"{shown_path(self.parts)}: a file may be at most {shown_size(cap)} on this "
                "server: the upload was stopped",
            )
        if end > self.reserved:
            self.files.reserve(end - self.reserved, 0, self.parts)
            self.reserved = end

    def commit(self) -> None:
        """Put the file in its place; the quota counts it from now on, whatever it replaced."""
        files = self.files
        try:
            files._folder_of(self.parts)
            replaced = files._file_size(self.target, self.parts)
            size = self.pending.size()
            self.pending.commit(self.target)
        except OSError as exc:
            self.abandon()
            raise _refusal(exc, self.parts) from None
        except BaseException:
            self.abandon()
            raise
        with files._lock:
            files.usage.reserved_bytes -= self.reserved
            files.usage.reserved_files -= self.file_slot
            files.usage.bytes += size - (replaced or 0)
            files.usage.files += 0 if replaced is not None else 1
        self.reserved = self.file_slot = 0
        files._changed(self.parts)

    def abandon(self) -> None:
        """Drop the upload: nothing is seen under its name, and its room is free again."""
        self.pending.discard()
        self.files.release(self.reserved, self.file_slot)
        self.reserved = self.file_slot = 0

    @property
    def done(self) -> bool:
        return not self.pending.open


def _entry(name: str, info: os.stat_result) -> Entry:
    return Entry(name, stat.S_ISDIR(info.st_mode), info.st_size, info.st_mtime, info.st_atime)


def _refusal(exc: OSError, parts: Parts) -> WorkspaceError:
    shown = shown_path(parts)
    kinds = {
        errno.ENOENT: (Refusal.MISSING, "no such file or folder"),
        errno.EEXIST: (Refusal.EXISTS, "is there already"),
        errno.ENOTEMPTY: (Refusal.NOT_EMPTY, "the folder is not empty"),
        errno.ENOTDIR: (Refusal.NOT_A_FOLDER, "a part of the path is not a folder"),
        errno.EISDIR: (Refusal.IS_A_FOLDER, "is a folder"),
        errno.ELOOP: (Refusal.DENIED, "is a link, which is not followed"),
        errno.EINVAL: (Refusal.DENIED, "cannot be moved there"),
    }
    kind, words = kinds.get(exc.errno or 0, (Refusal.FAILED, exc.strerror or str(exc)))
    return WorkspaceError(kind, f"{shown}: {words}")
