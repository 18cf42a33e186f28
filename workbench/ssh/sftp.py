"""SFTP on the lab server: a student's ``sftp`` and ``scp`` see their workspace as ``/`` and
nothing else; an instructor sees every workspace, read-only, as ``/NAME/...``.

Every file operation goes through the workspace's :class:`WorkspaceFiles` (confinement, the
upload limits and quota, uploads written whole or not at all); this module speaks the protocol:
it turns a client's paths into workspace paths (refusing bad ones with the reason), a refusal
into an SFTP status whose message says why (and one line on the channel's error output, which
OpenSSH's ``sftp`` and ``scp`` print), and logs one line per file opened.

Replies are flow-controlled as OpenSSH's sftp-server does it: a channel's requests are
answered one at a time, and the next is read only once the reply before it has left the
channel's output buffer (below asyncssh's high-water mark, 64 KiB), so a client that asks and
never reads what it asked for stops its own requests; one read's reply is at most
:data:`MAX_READ` bytes. Listings and file reads run in worker threads, never on the event
loop that serves every student.
"""

from __future__ import annotations

import asyncio
import contextlib
import logging
import os
import stat
from collections.abc import AsyncIterator, Awaitable, Callable
from dataclasses import dataclass, field
from typing import BinaryIO

import asyncssh
from asyncssh.channel import SSHChannel
from asyncssh.packet import SSHPacket
from asyncssh.sftp import (
    FXF_APPEND,
    FXF_CREAT,
    FXF_EXCL,
    FXF_READ,
    FXF_TRUNC,
    FXF_WRITE,
    FXP_OPENDIR,
    SFTPServerHandler,
)
from asyncssh.stream import SSHReader, SSHServerStreamSession, SSHWriter

from workbench.door.users import User
from workbench.door.workers import FILES, in_pool
from workbench.files.names import (
    MAX_NAME_BYTES,
    BadPath,
    Parts,
    path_parts,
    resolved_parts,
    shown_path,
)
from workbench.files.workspace import workspace_folder, workspaces_folder
from workbench.files.workspace_files import (
    Refusal,
    Upload,
    UploadLimits,
    WorkspaceError,
    WorkspaceFiles,
)

log = logging.getLogger("workbench.ssh")

#: files and folders one SFTP channel may hold open at once (each file holds a descriptor)
MAX_OPEN_FILES = 32
#: files one student may hold open over all their transfers (with 10 transfers of 32 each, four
#: students took every descriptor of a server with a limit of 1,024)
MAX_OPEN_FILES_PER_STUDENT = 64
MAX_OPEN_FOLDERS = 32
#: refusal lines written to one channel's error output; the rest go as SFTP statuses only
MAX_SAID = 50
#: the most bytes one read sends back (a client asking for more gets this much, which SFTP
#: allows: it reads on from where the reply ended), as OpenSSH's sftp-server caps it
MAX_READ = 256 * 1024
#: bytes of a transfer's requests taken off the channel and waiting to be handled
REQUESTS_WAITING = 256 * 1024
#: what a client reads when a file or folder cannot be opened for want of descriptors
OUT_OF_FILES = "the lab server has too many files open just now: try again in a few minutes"

_ERRORS: dict[Refusal, Callable[[str], asyncssh.SFTPError]] = {
    Refusal.MISSING: asyncssh.SFTPNoSuchFile,
    Refusal.EXISTS: asyncssh.SFTPFileAlreadyExists,
    Refusal.DENIED: asyncssh.SFTPPermissionDenied,
    Refusal.TOO_BIG: asyncssh.SFTPQuotaExceeded,
    Refusal.QUOTA: asyncssh.SFTPQuotaExceeded,
    Refusal.NOT_A_FOLDER: asyncssh.SFTPNotADirectory,
    Refusal.IS_A_FOLDER: asyncssh.SFTPFileIsADirectory,
    Refusal.NOT_EMPTY: asyncssh.SFTPDirNotEmpty,
    Refusal.FAILED: asyncssh.SFTPFailure,
}


class SFTPService:
    """The server's SFTP side: one :class:`WorkspaceFiles` per student while they have SFTP
    channels open (so racing uploads share one quota count), and the channels per user."""

    def __init__(
        self,
        data_dir: os.PathLike | str,
        limits: UploadLimits,
        room: Callable[[], bool] = lambda: True,
        say: Callable[[str, str], None] = lambda key, line: log.warning("%s", line),
    ) -> None:
        self.data_dir = data_dir
        self.limits = limits
        #: whether a file opened now stays out of the descriptors kept for the live sessions
        self.room = room
        #: logs a line an attacker could repeat (``say(key, line)``: repeats held back)
        self.say = say
        #: per student with transfers open: what their transfers share
        self._shares: dict[str, StudentShare] = {}
        self._files: dict[str, WorkspaceFiles] = {}
        self.channels: dict[str, int] = {}
        #: called with each change's workspace path, for a workspace kept elsewhere too
        self.on_change: Callable[[str, str], None] | None = None

    def open(self, user: User) -> WorkspaceFiles:
        """The files ``user`` sees; counted until :meth:`close`."""
        self.channels[user.name] = self.channels.get(user.name, 0) + 1
        if user.role == "instructor":
            root = workspaces_folder(self.data_dir)
            return WorkspaceFiles(root, self.limits, read_only=True, protected=())
        files = self._files.get(user.name)
        if files is None:
            hook = self.on_change
            files = self._files[user.name] = WorkspaceFiles(
                workspace_folder(self.data_dir, user.name),
                self.limits,
                on_change=(lambda path: hook(user.name, path)) if hook else None,
            )
        return files

    def share(self, user: User) -> StudentShare:
        """What the student's transfers share while any is open."""
        share = self._shares.get(user.name)
        if share is None:
            share = self._shares[user.name] = StudentShare()
        return share

    def workspace(self, name: str) -> WorkspaceFiles | None:
        """The files of student ``name`` while they have SFTP channels open."""
        return self._files.get(name)

    def close(self, user: User) -> None:
        left = self.channels.get(user.name, 0) - 1
        if left > 0:
            self.channels[user.name] = left
            return
        self.channels.pop(user.name, None)
        self._shares.pop(user.name, None)
        files = self._files.pop(user.name, None)  # counted afresh next time: the app writes too
        if files is not None:
            with contextlib.suppress(OSError):
                files.clear_uploads()

    def refusal(self, user: User, most: int) -> str | None:
        """Why ``user`` may not open one more SFTP channel, or None."""
        if self.channels.get(user.name, 0) < most:
            return None
        return (
            f"You already have {most} file transfers open, the most one user may have: "
            "wait for one to end and try again."
        )


@dataclass
class StudentShare:
    """What all of one student's transfers share: one listing at a time, and a count of the
    files they hold open."""

    listing_turn: asyncio.Lock = field(default_factory=asyncio.Lock)
    open_files: int = 0


@dataclass
class _Reading:
    parts: Parts
    file: BinaryIO
    sent: int = 0


@dataclass
class _Writing:
    parts: Parts
    upload: Upload
    append: bool = False
    refused: str = ""
    times: tuple[float, float] | None = None


_Open = _Reading | _Writing


class WorkspaceSFTPServer(asyncssh.SFTPServer):
    """One SFTP channel's requests, answered from one workspace's files."""

    def __init__(
        self,
        chan: asyncssh.SSHServerChannel,
        files: WorkspaceFiles,
        user: User,
        peer: str,
        room: Callable[[], bool] = lambda: True,
        say: Callable[[str, str], None] = lambda key, line: log.warning("%s", line),
        share: StudentShare | None = None,
    ) -> None:
        super().__init__(chan)
        self.files = files
        self.room = room
        self.say = say
        #: what the student's transfers share (one listing at a time, the files open)
        self.share = share or StudentShare()
        self.user = user
        self.peer = peer
        #: set when the client is gone: an upload still open then is dropped, not kept
        self.ending = False
        self._handles: dict[int, _Open] = {}
        #: refusal lines written to the client's error output so far
        self._said = 0

    # -- paths and refusals ------------------------------------------------------------------
    def _parts(self, raw: bytes, *, say: bool = True) -> Parts:
        try:
            return path_parts(raw)
        except BadPath as exc:
            if not say:  # a question before an upload or a rename, refused there with words
                raise asyncssh.SFTPInvalidFilename(str(exc)) from None
            raise self._refused(asyncssh.SFTPInvalidFilename, str(exc)) from None

    def _refused(
        self, kind: Callable[[str], asyncssh.SFTPError], message: str
    ) -> asyncssh.SFTPError:
        """The error to answer with; the reason also goes to the client's error output."""
        if self._said < MAX_SAID:
            self._said += 1
            with contextlib.suppress(Exception):
                self.channel.write_stderr(f"lab server: {message}\n".encode())
        return kind(message)

    def _refusal(self, exc: WorkspaceError) -> asyncssh.SFTPError:
        return self._refused(_ERRORS[exc.kind], exc.message)

    def _attrs(self, folder: bool, size: int, mtime: float, atime: float) -> asyncssh.SFTPAttrs:
        write = 0 if self.files.read_only else 0o200
        mode = (stat.S_IFDIR | 0o500 | write) if folder else (stat.S_IFREG | 0o400 | write)
        kind = asyncssh.FILEXFER_TYPE_DIRECTORY if folder else asyncssh.FILEXFER_TYPE_REGULAR
        return asyncssh.SFTPAttrs(
            type=kind,
            size=size,
            permissions=mode,
            uid=0,
            gid=0,
            atime=int(atime),
            mtime=int(mtime),
        )

    def format_user(self, uid: int | None) -> str:
        return self.user.name

    def format_group(self, gid: int | None) -> str:
        return self.user.name

    # -- reading -----------------------------------------------------------------------------
    def realpath(self, path: bytes) -> bytes:
        try:
            return shown_path(resolved_parts(path)).encode()
        except BadPath as exc:
            raise self._refused(asyncssh.SFTPInvalidFilename, str(exc)) from None

    def stat(self, path: bytes) -> asyncssh.SFTPAttrs:
        parts = self._parts(path, say=False)
        try:
            entry = self.files.stat(parts)
        except WorkspaceError as exc:
            raise self._quiet(exc) from None
        return self._attrs(entry.is_folder, entry.size, entry.mtime, entry.atime)

    lstat = stat

    def _quiet(self, exc: WorkspaceError) -> asyncssh.SFTPError:
        """A missing file is asked about all the time (``put`` checks first): no line said."""
        if exc.kind is Refusal.MISSING:
            return asyncssh.SFTPNoSuchFile(exc.message)
        return self._refusal(exc)

    async def scandir(self, path: bytes) -> AsyncIterator[asyncssh.SFTPName]:
        parts = self._parts(path)
        try:
            async with self.share.listing_turn:  # one listing of the student's at a time
                names = await in_pool(FILES, self._listing, parts)
        except WorkspaceError as exc:
            raise self._refusal(exc) from None
        for name in names:
            yield name

    def _listing(self, parts: Parts) -> list[asyncssh.SFTPName]:
        """A folder's names with their attributes (in a worker thread)."""
        entries, here = self.files.list(parts), self.files.stat(parts)
        dots = self._attrs(True, here.size, here.mtime, here.atime)
        names = [asyncssh.SFTPName(dot, attrs=dots) for dot in (b".", b"..")]
        for entry in entries:
            attrs = self._attrs(entry.is_folder, entry.size, entry.mtime, entry.atime)
            names.append(asyncssh.SFTPName(entry.name.encode(), attrs=attrs))
        return names

    def statvfs(self, path: bytes) -> asyncssh.SFTPVFSAttrs:
        """The room the quota leaves (``df`` in ``sftp``), never the server's disks."""
        parts = self._parts(path)
        try:
            self.files.stat(parts)
        except WorkspaceError as exc:
            raise self._refusal(exc) from None
        limits, usage = self.files.limits, self.files.usage
        if self.files.read_only or not (limits.quota_bytes and limits.quota_files):
            raise asyncssh.SFTPOpUnsupported("no quota to show here")
        used = usage.bytes + usage.reserved_bytes
        entries = usage.files + usage.reserved_files
        free = max(0, limits.quota_bytes - used)
        left = max(0, limits.quota_files - entries)
        return asyncssh.SFTPVFSAttrs(
            bsize=1, frsize=1, blocks=limits.quota_bytes, bfree=free, bavail=free,
            files=limits.quota_files, ffree=left, favail=left, namemax=MAX_NAME_BYTES,
        )  # fmt: skip

    def fstatvfs(self, file_obj: object) -> asyncssh.SFTPVFSAttrs:
        return self.statvfs(shown_path(self._handle(file_obj).parts).encode())

    def open56(
        self, path: bytes, desired_access: int, flags: int, attrs: asyncssh.SFTPAttrs
    ) -> object:
        raise asyncssh.SFTPOpUnsupported("this server speaks SFTP version 3")

    def readlink(self, path: bytes) -> bytes:
        raise self._refused(asyncssh.SFTPOpUnsupported, "links are not kept on this server")

    # -- open files --------------------------------------------------------------------------
    def open(self, path: bytes, pflags: int, attrs: asyncssh.SFTPAttrs) -> int:
        parts = self._parts(path)
        self.check_room()
        if len(self._handles) >= MAX_OPEN_FILES:
            raise self._refused(
                asyncssh.SFTPFailure,
                f"at most {MAX_OPEN_FILES} files can be open at once on one transfer: close some",
            )
        if self.share.open_files >= MAX_OPEN_FILES_PER_STUDENT:
            raise self._refused(
                asyncssh.SFTPFailure,
                f"at most {MAX_OPEN_FILES_PER_STUDENT} files can be open at once over all your "
                "transfers: close some",
            )
        handle: _Open
        try:
            if pflags & (FXF_WRITE | FXF_APPEND):
                handle = self._open_writing(parts, pflags)
            elif pflags & FXF_READ:
                handle = _Reading(parts, self.files.open_read(parts))
            else:
                raise self._refused(asyncssh.SFTPFailure, "open a file to read or to write it")
        except WorkspaceError as exc:
            what = "write" if pflags & (FXF_WRITE | FXF_APPEND) else "read"
            self._log(parts, what, 0, f"refused: {exc.message}")
            raise self._refusal(exc) from None
        key = id(handle)
        self._handles[key] = handle
        self.share.open_files += 1
        return key

    def check_room(self) -> None:
        """Refuse to open a file or folder while the server's last descriptors are all that is
        left (they are kept for the sessions already in)."""
        if not self.room():
            self.say(
                "sftp out of files",
                f"sftp: {self.user.name} from {self.peer}: open refused: few open files left",
            )
            raise self._refused(asyncssh.SFTPFailure, OUT_OF_FILES)

    def _open_writing(self, parts: Parts, pflags: int) -> _Writing:
        if not pflags & FXF_CREAT:
            self.files.stat(parts)  # a file that is not there is not made
        upload = self.files.begin_write(
            parts, keep=not pflags & FXF_TRUNC, exclusive=bool(pflags & FXF_EXCL)
        )
        return _Writing(parts, upload, append=bool(pflags & FXF_APPEND))

    async def read(self, file_obj: object, offset: int, size: int) -> bytes:
        handle = self._handle(file_obj)
        size = min(size, MAX_READ)
        if isinstance(handle, _Writing):
            return await in_pool(FILES, handle.upload.read, offset, size)
        data = await in_pool(FILES, os.pread, handle.file.fileno(), size, offset)
        handle.sent += len(data)
        return data

    def write(self, file_obj: object, offset: int, data: bytes) -> int:
        handle = self._handle(file_obj)
        if not isinstance(handle, _Writing):
            raise self._refused(asyncssh.SFTPPermissionDenied, "this file was opened to read")
        if handle.refused:
            raise asyncssh.SFTPFailure(handle.refused)
        try:
            handle.upload.write(handle.upload.size if handle.append else offset, data)
        except WorkspaceError as exc:
            handle.refused = exc.message
            handle.upload.abandon()  # its room is free again at once
            raise self._refusal(exc) from None
        except OSError as exc:
            handle.refused = f"{shown_path(handle.parts)}: {exc.strerror}"
            handle.upload.abandon()
            raise self._refused(asyncssh.SFTPFailure, handle.refused) from None
        return len(data)

    def fstat(self, file_obj: object) -> asyncssh.SFTPAttrs:
        handle = self._handle(file_obj)
        if isinstance(handle, _Writing):
            size = 0 if handle.upload.done else handle.upload.size
            return self._attrs(False, size, 0, 0)
        info = os.fstat(handle.file.fileno())
        return self._attrs(False, info.st_size, info.st_mtime, info.st_atime)

    def fsync(self, file_obj: object) -> None:
        self._handle(file_obj)  # an upload is flushed to the disk when it is closed

    async def close(self, file_obj: object) -> None:
        handle = self._handles.pop(file_obj, None)  # type: ignore[call-overload]
        if handle is None:
            return
        self.share.open_files -= 1
        if isinstance(handle, _Reading):
            handle.file.close()
            self._log(handle.parts, "read", handle.sent, "done")
            return
        upload = handle.upload
        if handle.refused:
            self._log(handle.parts, "write", upload.size, f"refused: {handle.refused}")
            return
        if self.ending:
            upload.abandon()
            self._log(handle.parts, "write", upload.size, "dropped: the client left mid-way")
            return
        try:  # flushed to the disk away from the loop that serves every student
            await in_pool(FILES, upload.commit)
            if handle.times is not None:
                self.files.set_times(handle.parts, *handle.times)
        except WorkspaceError as exc:
            self._log(handle.parts, "write", upload.size, f"failed: {exc.message}")
            raise self._refusal(exc) from None
        self._log(handle.parts, "write", upload.size, "done")

    def _handle(self, file_obj: object) -> _Open:
        handle = self._handles.get(file_obj)  # type: ignore[call-overload]
        if handle is None:
            raise asyncssh.SFTPInvalidHandle("no such open file")
        return handle

    async def exit(self) -> None:
        for key in list(self._handles):
            self.ending = True
            await self.close(key)

    # -- attributes --------------------------------------------------------------------------
    def _check_attrs(self, attrs: asyncssh.SFTPAttrs, parts: Parts) -> None:
        if attrs.uid is not None or attrs.gid is not None or attrs.owner or attrs.group:
            raise self._refused(
                asyncssh.SFTPPermissionDenied,
                f"{shown_path(parts)}: files here belong to the server; owners cannot be changed",
            )
        if attrs.permissions is not None and attrs.permissions & 0o7777 & ~0o666:
            raise self._refused(
                asyncssh.SFTPPermissionDenied,
                f"{shown_path(parts)}: only read and write permissions are kept here (asked "
                f"for {attrs.permissions & 0o7777:04o}); files on the lab server are never run",
            )

    def setstat(self, path: bytes, attrs: asyncssh.SFTPAttrs) -> None:
        parts = self._parts(path)
        self._check_attrs(attrs, parts)
        if attrs.size is not None:
            raise self._refused(
                asyncssh.SFTPOpUnsupported,
                f"{shown_path(parts)}: a file's size changes only by uploading it again",
            )
        try:
            if attrs.mtime is not None:
                self.files.set_times(parts, attrs.atime or attrs.mtime, attrs.mtime)
            else:
                self.files.stat(parts)
        except WorkspaceError as exc:
            raise self._refusal(exc) from None

    lsetstat = setstat

    def fsetstat(self, file_obj: object, attrs: asyncssh.SFTPAttrs) -> None:
        handle = self._handle(file_obj)
        self._check_attrs(attrs, handle.parts)
        if not isinstance(handle, _Writing):
            if attrs.size is not None or attrs.mtime is not None:
                raise self._refused(asyncssh.SFTPPermissionDenied, "this file was opened to read")
            return
        try:
            if attrs.size is not None:
                handle.upload.truncate(attrs.size)
        except WorkspaceError as exc:
            handle.refused = exc.message
            handle.upload.abandon()
            raise self._refusal(exc) from None
        if attrs.mtime is not None:
            handle.times = (attrs.atime or attrs.mtime, attrs.mtime)

    # -- changes -----------------------------------------------------------------------------
    def _change(self, what: str, run: Callable[[], None], parts: Parts) -> None:
        try:
            run()
        except WorkspaceError as exc:
            log.info("sftp: %s %s %s: refused: %s", self.user.name, what, shown_path(parts), exc)
            raise self._refusal(exc) from None
        log.info("sftp: %s %s %s", self.user.name, what, shown_path(parts))

    def remove(self, path: bytes) -> None:
        parts = self._parts(path)
        self._change("removed", lambda: self.files.remove(parts), parts)

    def mkdir(self, path: bytes, attrs: asyncssh.SFTPAttrs) -> None:
        parts = self._parts(path)
        self._change("made folder", lambda: self.files.mkdir(parts), parts)

    def rmdir(self, path: bytes) -> None:
        parts = self._parts(path)
        self._change("removed folder", lambda: self.files.rmdir(parts), parts)

    def rename(self, oldpath: bytes, newpath: bytes) -> None:
        old, new = self._parts(oldpath), self._parts(newpath)
        self._change(f"renamed {shown_path(old)} to", lambda: self.files.rename(old, new), new)

    def posix_rename(self, oldpath: bytes, newpath: bytes) -> None:
        old, new = self._parts(oldpath), self._parts(newpath)
        self._change(
            f"renamed {shown_path(old)} to",
            lambda: self.files.rename(old, new, replace=True),
            new,
        )

    def symlink(self, oldpath: bytes, newpath: bytes) -> None:
        self._no_links(newpath)

    def link(self, oldpath: bytes, newpath: bytes) -> None:
        self._no_links(newpath)

    def _no_links(self, newpath: bytes) -> None:
        log.warning("sftp: %s from %s: link refused", self.user.name, self.peer)
        raise self._refused(
            asyncssh.SFTPPermissionDenied,
            "links cannot be made on this server: upload the file itself",
        )

    def _log(self, parts: Parts, what: str, size: int, outcome: str) -> None:
        log.info(
            "sftp: %s %s %s: %d bytes: %s", self.user.name, what, shown_path(parts), size, outcome
        )


class _Handler(SFTPServerHandler):
    """asyncssh's SFTP protocol, told when the client has gone (so an open upload is dropped,
    not kept), with the folders one channel holds open capped, and each reply out of the
    channel's buffer before the next request is read."""

    _packet_handlers = dict(SFTPServerHandler._packet_handlers)  # noqa: RUF012

    async def _process_packet(self, pkttype: int, pktid: int, packet: SSHPacket) -> None:
        await super()._process_packet(pkttype, pktid, packet)
        if self._writer is not None:
            # asyncssh buffers what the client's window does not take yet without a bound:
            # wait (reading no more requests) until it is below the high-water mark
            await self._writer.drain()

    async def _cleanup(self, exc: Exception | None) -> None:
        server = self._server
        if isinstance(server, WorkspaceSFTPServer):
            server.ending = True
            with contextlib.suppress(Exception):  # before the channel closes: OpenSSH reads it
                server.channel.exit(0 if exc is None else 1)
        await super()._cleanup(exc)

    async def _process_opendir(self, packet: SSHPacket) -> bytes:
        server = self._server
        if isinstance(server, WorkspaceSFTPServer):
            server.check_room()
        if len(self._dir_handles) >= MAX_OPEN_FOLDERS:
            raise asyncssh.SFTPFailure(
                f"at most {MAX_OPEN_FOLDERS} folders can be open at once: close some"
            )
        return await SFTPServerHandler._process_opendir(self, packet)

    _packet_handlers[FXP_OPENDIR] = _process_opendir  # type: ignore[assignment]


@dataclass
class SFTPChannel:
    """A session channel that asked for the ``sftp`` subsystem: the protocol runs on it once
    it is let in; the lab session passes the channel's events here."""

    service: SFTPService
    user: User
    peer: str
    stream: _Stream = field(init=False)
    server: WorkspaceSFTPServer | None = None

    def __post_init__(self) -> None:
        self.stream = _Stream(self._run)

    def connection_made(self, chan: asyncssh.SSHServerChannel) -> None:
        self.stream.connection_made(chan)

    def start(self, chan: asyncssh.SSHServerChannel, most: int) -> None:
        """Run the protocol on ``chan``, or refuse it (past the user's transfers)."""
        why = self.service.refusal(self.user, most)
        if why is not None:
            log.warning("sftp refused: %s from %s: %s", self.user.name, self.peer, why)
            chan.write_stderr(why.encode() + b"\r\n")
            chan.exit(1)
            return
        try:
            files = self.service.open(self.user)
        except OSError as exc:
            self.service.close(self.user)
            log.error("sftp: %s's workspace cannot be used: %s", self.user.name, exc)
            chan.write_stderr(b"Your workspace cannot be used now; tell the instructor.\r\n")
            chan.exit(1)
            return
        service = self.service
        self.server = WorkspaceSFTPServer(
            chan, files, self.user, self.peer, service.room, service.say,
            service.share(self.user),
        )  # fmt: skip
        log.info("sftp: %s (%s) from %s", self.user.name, self.user.role, self.peer)
        self.stream.session_started()

    async def _run(self, reader: SSHReader[bytes], writer: SSHWriter[bytes]) -> None:
        assert self.server is not None
        try:
            await _Handler(self.server, reader, writer, 3).run()
        finally:
            self.service.close(self.user)


class _Stream(SSHServerStreamSession):
    """The channel's bytes as a stream, read and written by the SFTP protocol."""

    def __init__(
        self, run: Callable[[SSHReader[bytes], SSHWriter[bytes]], Awaitable[None]]
    ) -> None:
        super().__init__(None)
        self._run = run

    def connection_made(self, chan: SSHChannel[bytes]) -> None:
        super().connection_made(chan)
        # requests read from the channel and not handled yet: past this the channel stops
        # taking them (and so stops widening the client's window) until the handler catches up
        self._limit = REQUESTS_WAITING

    def session_started(self) -> None:
        assert self._chan is not None and self._conn is not None
        reader = SSHReader[bytes](self, self._chan)
        self._conn.create_task(self._run(reader, SSHWriter[bytes](self, self._chan)))
