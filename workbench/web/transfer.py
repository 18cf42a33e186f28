"""Files through the browser: uploads into the student's workspace and downloads from it.

An upload goes through :class:`workbench.files.workspace_files.WorkspaceFiles`, as an SFTP
upload does: the name checked by :mod:`workbench.files.names` (no ``..``, no hidden or
reserved names, no control characters), written under a hidden name and renamed whole, within
the student's file size cap and quota; the run records the app keeps (``runs/``) are never
written. A download reads any file of the workspace (run records, pictures, programs) by a
path the same rules check, so no path leads out of it.
"""

from __future__ import annotations

from dataclasses import dataclass

from workbench.files.names import BadPath, path_parts, shown_path
from workbench.files.workspace_files import (
    ChangeHook,
    Entry,
    UploadLimits,
    WorkspaceError,
    WorkspaceFiles,
)

#: how a download is named to the browser: its last part, with only these characters kept
_SAFE = frozenset("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789._-")


class TransferError(ValueError):
    """A file refused, with the reason a student reads."""


@dataclass(frozen=True)
class Listing:
    folder: str
    entries: tuple[Entry, ...]


def files_of(root, limits: UploadLimits, on_change: ChangeHook | None = None) -> WorkspaceFiles:
    """The workspace's files as the browser door uses them (the app may be writing there at
    the same time: the room is counted afresh for each upload); ``on_change`` hears of each
    file written (to send it on to the course store)."""
    return WorkspaceFiles(root, limits, shared=True, on_change=on_change)


def upload(files: WorkspaceFiles, name: str, data: bytes) -> str:
    """Write ``data`` as ``name`` (a path in the workspace: the folder the files panel shows,
    then the file's name) in the workspace; the path written, as shown."""
    try:
        parts = path_parts(name)
    except BadPath as exc:
        raise TransferError(f"{name[:80]!r}: {exc}") from None
    if not parts:
        raise TransferError("give the file a name")
    try:
        writing = files.begin_write(parts)
        try:
            writing.write(0, data)
            writing.commit()
        except BaseException:
            writing.abandon()
            raise
    except WorkspaceError as exc:
        raise TransferError(exc.message) from None
    return shown_path(parts)


def read(files: WorkspaceFiles, path: str, limit: int) -> tuple[str, bytes]:
    """The file at ``path`` in the workspace: the name to save it as and its bytes (at most
    ``limit``)."""
    try:
        parts = path_parts(path)
    except BadPath as exc:
        raise TransferError(f"{path[:80]!r}: {exc}") from None
    if not parts:
        raise TransferError("name a file to download")
    try:
        with files.open_read(parts) as source:
            data = source.read(limit + 1)
    except WorkspaceError as exc:
        raise TransferError(exc.message) from None
    if len(data) > limit:
        raise TransferError(f"{shown_path(parts)} is larger than {limit} bytes")
    name = "".join(c if c in _SAFE else "_" for c in parts[-1]) or "file"
    return name, data


def listing(files: WorkspaceFiles, folder: str) -> Listing:
    try:
        parts = path_parts(folder)
        return Listing(shown_path(parts), tuple(files.list(parts)))
    except BadPath as exc:
        raise TransferError(f"{folder[:80]!r}: {exc}") from None
    except WorkspaceError as exc:
        raise TransferError(exc.message) from None
