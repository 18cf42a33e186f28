"""One workspace for the course: a served student's workspace folder kept in step with the
course store, so that their files follow them to any lab server.

The app, the lab checks and the file transfers keep reading and writing the workspace folder
on this server's disk; this module copies it to and from the store's workspace files
(:mod:`.workspace_rows`):

* :func:`pull_workspace`, when a session starts: the files the store has that are newer than
  this server's copy are written into the folder, the files removed elsewhere are removed
  here, and the files changed here while the store could not be reached are sent.
* :func:`push_file` / :func:`remove_file`: one file sent to the store (or marked removed) at
  once, for whatever has just committed a file (the SFTP server after an upload). Each call
  waits for the database (up to its statement deadline): call it from a thread, never on an
  event loop. The bounds it enforces are :data:`~.workspace_rows.LIMITS`, and the names it
  takes are those :func:`~.workspace_rows.check_path` passes.
* :class:`WorkspacePusher`: the app's files sent as it commits them (the atomic writer and a
  closed run record announce them, :mod:`workbench.files.commits`), in a thread of its own
  with a store connection of its own, so a store that hangs never holds up the app; a push
  that fails is tried again, and the student is told only when it keeps failing.

Which side is newer is decided with what this server last saw of each file, kept beside the
workspaces (``<data-dir>/workspaces/.sync/<user>.json``: per path the store's revision and
the file's SHA-256, size and modification time): a file that changed only on one side goes
the other way; a file that changed on both keeps the one modified last. Names the store does
not take (:func:`~.workspace_rows.check_path`) and files past its bounds stay on this server
only, and the student is told why.
"""

from __future__ import annotations

import contextlib
import fcntl
import hashlib
import json
import logging
import os
import stat
import threading
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field
from pathlib import Path

from workbench.files.atomic import write_bytes_atomic
from workbench.files.commits import forget, on_commit
from workbench.files.reserved import reserved_problem

from .database import StoreError, StoreUnavailable
from .store import Store
from .workspace_rows import (
    LIMITS,
    FileRow,
    WorkspaceLimits,
    WorkspaceRefused,
    check_path,
    sha256_hex,
)

log = logging.getLogger(__name__)

#: the folder beside the workspaces where each one's last seen state is kept
SYNC_DIR = ".sync"
#: the largest state file read (a workspace of the most files fits well within it)
MAX_STATE_BYTES = 4 * 1024 * 1024
#: seconds between tries of a push that failed, at first and at most
RETRY_FIRST_S = 1.0
RETRY_MOST_S = 30.0
#: failed tries of one file before the student is told
TELL_AFTER = 3
#: seconds with nothing to send after which the pusher gives its connection back
IDLE_CLOSE_S = 60.0


@dataclass
class Seen:
    """A file as this server last saw it in step with the store."""

    sha256: str
    revision: int
    size: int
    mtime_ns: int

    def to_json(self) -> list[object]:
        return [self.sha256, self.revision, self.size, self.mtime_ns]

    @classmethod
    def from_json(cls, value: object) -> Seen | None:
        if not isinstance(value, list) or len(value) != 4:
            return None
        sha, revision, size, mtime_ns = value
        if not (isinstance(sha, str) and all(isinstance(v, int) for v in value[1:])):
            return None
        return cls(sha, revision, size, mtime_ns)


@dataclass
class SyncReport:
    """What one :func:`pull_workspace` did, and the files it left alone with the reason."""

    fetched: list[str] = field(default_factory=list)
    removed: list[str] = field(default_factory=list)
    pushed: list[str] = field(default_factory=list)
    problems: list[str] = field(default_factory=list)


def state_path(folder: Path) -> Path:
    """Where the last seen state of the workspace ``folder`` is kept."""
    return folder.parent / SYNC_DIR / f"{folder.name}.json"


@contextlib.contextmanager
def _state(folder: Path) -> Iterator[dict[str, Seen]]:
    """The workspace's last seen state, held for changing (one process at a time) and
    written back whole afterwards: also when the work stopped half way, since what it holds
    is what was done."""
    path = state_path(folder)
    path.parent.mkdir(parents=True, exist_ok=True, mode=0o700)
    with open(path.with_suffix(".lock"), "a") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        try:
            state = _load_state(path)
            before = dict(state)
            try:
                yield state
            finally:
                if state != before:
                    text = json.dumps({p: s.to_json() for p, s in sorted(state.items())})
                    write_bytes_atomic(path, text.encode(), 0o600)
        finally:
            fcntl.flock(lock, fcntl.LOCK_UN)


def _load_state(path: Path) -> dict[str, Seen]:
    try:
        with open(path, "rb") as fh:
            raw = fh.read(MAX_STATE_BYTES + 1)
    except FileNotFoundError:
        return {}
    if len(raw) > MAX_STATE_BYTES:
        log.warning("%s: larger than %d bytes: started again", path, MAX_STATE_BYTES)
        return {}
    try:
        data = json.loads(raw)
    except ValueError:
        log.warning("%s: not JSON: started again", path)
        return {}
    if not isinstance(data, dict):
        return {}
    out = {}
    for key, value in data.items():
        seen = Seen.from_json(value)
        if isinstance(key, str) and seen is not None:
            out[key] = seen
    return out


def relative_path(folder: Path, path: str | os.PathLike) -> str | None:
    """``path`` as a path inside the workspace ``folder`` (``runs/x/run-1.jsonl``), or None
    when it is elsewhere (or is the folder)."""
    full = Path(os.path.abspath(path))
    root = Path(os.path.abspath(folder))
    if full == root or not full.is_relative_to(root):
        return None
    return full.relative_to(root).as_posix()


def _inside(folder: Path, relpath: str) -> Path:
    """The file ``relpath`` names in ``folder``, refused when a link would take it outside."""
    check_path(relpath)
    full = folder / relpath
    root = folder.resolve()
    if not full.parent.resolve().is_relative_to(root):
        raise WorkspaceRefused(f"{relpath}: its folder leads outside the workspace")
    return full


def read_local(full: Path, cap: int) -> tuple[bytes, os.stat_result] | None:
    """A regular file's bytes (at most ``cap``) and status, never through a link; None when
    there is no such file. :class:`WorkspaceRefused` for a larger file or a non-file."""
    try:
        fd = os.open(full, os.O_RDONLY | os.O_NOFOLLOW | os.O_NONBLOCK | os.O_CLOEXEC)
    except FileNotFoundError:
        return None
    except OSError as exc:
        raise WorkspaceRefused(f"{full.name}: cannot be read ({exc.strerror})") from None
    with os.fdopen(fd, "rb") as fh:
        info = os.fstat(fd)
        if not stat.S_ISREG(info.st_mode):
            raise WorkspaceRefused(f"{full.name}: not a regular file")
        if info.st_size > cap:
            raise WorkspaceRefused(
                f"{full.name}: {info.st_size / 1048576:.3g} MiB is more than the "
                f"{cap / 1048576:.3g} MiB a file may take in the course store"
            )
        data = fh.read(cap + 1)
    if len(data) > cap:
        raise WorkspaceRefused(f"{full.name}: grew past {cap} bytes while it was read")
    return data, info


def push_file(
    store: Store,
    user: str,
    relpath: str,
    folder: str | os.PathLike,
    limits: WorkspaceLimits = LIMITS,
) -> FileRow | None:
    """Send the file ``relpath`` of ``user``'s workspace ``folder`` to the store now (or mark
    it removed there when it is gone from the folder). Call it after the file is complete on
    disk. Returns the file's row as stored (None: removed). Raises
    :class:`~.workspace_rows.WorkspaceRefused` (a bound or a name the store does not take),
    :class:`StoreUnavailable` (the database is away; try again later) or
    :class:`StoreError`."""
    root = Path(folder)
    with _state(root) as state:
        return _send(store, user, relpath, root, limits, state)


def push_path(
    store: Store,
    user: str,
    relpath: str,
    folder: str | os.PathLike,
    limits: WorkspaceLimits = LIMITS,
) -> None:
    """Bring what ``relpath`` names in the workspace ``folder`` to the store, whatever it is
    now: a file is sent; a folder (made, or renamed here) has every file in it sent; a path
    gone (a file or a folder removed or renamed away) is marked removed, with every file the
    store holds under it. Raises as :func:`push_file`."""
    root = Path(folder)
    full = _inside(root, relpath)
    with _state(root) as state:
        if full.is_dir() and not full.is_symlink():
            found, _left_out = local_files(root, limits)
            for rel in found:
                if rel.startswith(relpath + "/"):
                    _send(store, user, rel, root, limits, state)
            return
        _send(store, user, relpath, root, limits, state)
        if not full.exists():
            inside = relpath + "/"
            for rel, row in store.workspaces.index(user).items():
                if rel.startswith(inside) and not row.deleted and not (root / rel).exists():
                    _unsend(store, user, rel, state)


def remove_file(store: Store, user: str, relpath: str, folder: str | os.PathLike) -> FileRow | None:
    """Mark the file ``relpath`` of ``user``'s workspace removed in the store (call it once
    it is removed from the folder ``folder``); None when the store did not hold it. Raises as
    :func:`push_file`."""
    with _state(Path(folder)) as state:
        return _unsend(store, user, relpath, state)


def _send(
    store: Store,
    user: str,
    relpath: str,
    root: Path,
    limits: WorkspaceLimits,
    state: dict[str, Seen],
) -> FileRow | None:
    full = _inside(root, relpath)
    local = read_local(full, limits.file_cap)
    if local is None:
        return _unsend(store, user, relpath, state)
    data, info = local
    row = store.workspaces.put(user, relpath, data, info.st_mtime, limits)
    state[relpath] = Seen(row.sha256, row.revision, info.st_size, info.st_mtime_ns)
    return row


def _unsend(store: Store, user: str, relpath: str, state: dict[str, Seen]) -> FileRow | None:
    check_path(relpath)
    row = store.workspaces.remove(user, relpath)
    state.pop(relpath, None)
    return row


def local_files(
    folder: Path, limits: WorkspaceLimits = LIMITS
) -> tuple[dict[str, os.stat_result], list[str]]:
    """The regular files of the workspace ``folder`` the store may keep, by path, never
    following links; and what was left out (hidden names are the workbench's own and left
    out without a word). At most twice the file bound is looked at."""
    found: dict[str, os.stat_result] = {}
    problems: list[str] = []
    pending = [folder]
    seen = 0
    while pending:
        current = pending.pop()
        try:
            entries = sorted(os.scandir(current), key=lambda e: e.name)
        except OSError as exc:
            problems.append(f"{current}: cannot be read ({exc.strerror})")
            continue
        for entry in entries:
            seen += 1
            if seen > 2 * limits.files:
                problems.append(f"more than {2 * limits.files} entries: the rest are not copied")
                return found, problems
            if entry.name.startswith("."):
                continue
            rel = relative_path(folder, entry.path)
            if rel is None:
                continue
            try:
                check_path(rel)
            except WorkspaceRefused as exc:
                problems.append(str(exc))
                continue
            if entry.is_dir(follow_symlinks=False):
                pending.append(Path(entry.path))
            elif entry.is_file(follow_symlinks=False):
                with contextlib.suppress(OSError):
                    found[rel] = entry.stat(follow_symlinks=False)
    return found, problems


def _local_sha(root: Path, rel: str, info: os.stat_result, seen: Seen | None) -> str:
    if seen is not None and seen.size == info.st_size and seen.mtime_ns == info.st_mtime_ns:
        return seen.sha256  # unchanged since it was last in step
    try:
        fd = os.open(root / rel, os.O_RDONLY | os.O_NOFOLLOW | os.O_NONBLOCK | os.O_CLOEXEC)
        with os.fdopen(fd, "rb") as fh:
            return hashlib.file_digest(fh, "sha256").hexdigest()
    except OSError:
        return ""


def pull_workspace(
    store: Store, user: str, folder: str | os.PathLike, limits: WorkspaceLimits = LIMITS
) -> SyncReport:
    """Bring ``user``'s workspace ``folder`` in step with the store (see the module's notes);
    a file that cannot be brought is named in the report and the rest go on. Raises
    :class:`StoreUnavailable` when the database is away (the folder is left as it is, save
    what was done before). The workspace's state is held for the whole pull (a send of the
    same workspace waits for it) and written once."""
    root = Path(folder)
    root.mkdir(parents=True, exist_ok=True, mode=0o700)
    report = SyncReport()
    with _state(root) as state:
        remote = store.workspaces.index(user)
        local, problems = local_files(root, limits)
        report.problems.extend(problems)
        for rel in sorted(set(remote) | set(local) | set(state)):
            row, info, seen = remote.get(rel), local.get(rel), state.get(rel)
            sha = _local_sha(root, rel, info, seen) if info is not None else None
            step = _Step(store, user, root, limits, state, report)
            try:
                step.settle(rel, row, info, sha, seen)
            except WorkspaceRefused as exc:
                report.problems.append(str(exc))
            except StoreUnavailable:
                raise
            except StoreError as exc:
                report.problems.append(f"{rel}: {exc}")
            except OSError as exc:
                report.problems.append(f"{rel}: cannot be written here ({exc.strerror or exc})")
    return report


@dataclass
class _Step:
    """Bringing one file in step, within a pull (the table of cases is the module's notes)."""

    store: Store
    user: str
    root: Path
    limits: WorkspaceLimits
    state: dict[str, Seen]
    report: SyncReport

    def settle(
        self,
        rel: str,
        row: FileRow | None,
        info: os.stat_result | None,
        sha: str | None,
        seen: Seen | None,
    ) -> None:
        if row is not None and not row.deleted:
            if sha == row.sha256:
                assert info is not None
                self.state[rel] = Seen(sha, row.revision, info.st_size, info.st_mtime_ns)
            elif sha is None:
                if seen is not None and seen.revision >= row.revision:
                    self.remove_there(rel)  # removed here, not changed there since
                else:
                    self.fetch(rel)
            else:
                assert info is not None
                changed_here = seen is None or sha != seen.sha256
                changed_there = seen is None or row.revision > seen.revision
                if changed_here and (not changed_there or info.st_mtime > row.mtime):
                    self.send(rel)
                else:
                    self.fetch(rel)
        elif row is not None:  # removed elsewhere
            if sha is None:
                self.state.pop(rel, None)
            elif seen is not None and sha == seen.sha256 and row.revision > seen.revision:
                self.remove_here(rel)
            else:  # changed here after (or never in step): kept, and sent
                self.send(rel)
        elif sha is not None:  # new here, or made while the store was away
            self.send(rel)
        else:
            self.state.pop(rel, None)

    def send(self, rel: str) -> None:
        _send(self.store, self.user, rel, self.root, self.limits, self.state)
        self.report.pushed.append(rel)

    def remove_there(self, rel: str) -> None:
        _unsend(self.store, self.user, rel, self.state)
        self.report.removed.append(rel)

    def fetch(self, rel: str) -> None:
        got = self.store.workspaces.file(self.user, rel)
        if got is None:
            return
        row, data = got
        if sha256_hex(data) != row.sha256:
            self.report.problems.append(
                f"{rel}: the store's copy does not match its digest: not taken"
            )
            return
        root = self.root
        full = _inside(root, rel)
        _make_folders(root, full.parent)
        if full.is_symlink() or (full.exists() and not full.is_file()):
            self.report.problems.append(f"{rel}: something that is not a file is in its place")
            return
        if reserved_problem(tuple(rel.split("/"))) and full.exists():
            # the recorder writes a run record once: another copy under its name is not its
            self.report.problems.append(
                f"{rel}: a run record is never changed once written: this server's copy is kept"
            )
            return
        write_bytes_atomic(full, data, 0o600)
        os.utime(full, (row.mtime, row.mtime), follow_symlinks=False)
        info = full.stat(follow_symlinks=False)
        self.state[rel] = Seen(row.sha256, row.revision, info.st_size, info.st_mtime_ns)
        self.report.fetched.append(rel)

    def remove_here(self, rel: str) -> None:
        full = _inside(self.root, rel)
        with contextlib.suppress(FileNotFoundError):
            if full.is_file() and not full.is_symlink():
                full.unlink()
        self.state.pop(rel, None)
        self.report.removed.append(rel)


def _make_folders(root: Path, folder: Path) -> None:
    """Make ``folder`` (inside ``root``) and the folders above it, refusing any that is a
    link or a file."""
    for part in reversed([folder, *folder.parents]):
        if part == root or not part.is_relative_to(root):
            continue
        if part.is_symlink() or (part.exists() and not part.is_dir()):
            raise WorkspaceRefused(f"{part.relative_to(root)}: not a folder here")
        if not part.exists():
            part.mkdir(mode=0o700)


class WorkspacePusher:
    """Sends each file the app commits inside the workspace ``folder`` to the store, from a
    thread of its own with a store of its own (``open_store`` makes it there). A push that
    fails is tried again, sooner at first, then every :data:`RETRY_MOST_S`; ``tell`` (called
    from that thread) says so once a file has failed :data:`TELL_AFTER` times, again when it
    is sent, and at once when the store refuses a file. After ``idle_close`` seconds with
    nothing to send it gives its connection back."""

    def __init__(
        self,
        open_store: Callable[[], Store],
        user: str,
        folder: str | os.PathLike,
        tell: Callable[[str], None],
        limits: WorkspaceLimits = LIMITS,
        retry_first: float = RETRY_FIRST_S,
        retry_most: float = RETRY_MOST_S,
        idle_close: float = IDLE_CLOSE_S,
    ) -> None:
        self.open_store = open_store
        self.user = user
        self.folder = Path(os.path.abspath(folder))
        self.tell = tell
        self.limits = limits
        self.retry_first = retry_first
        self.retry_most = retry_most
        self.idle_close = idle_close
        self._cond = threading.Condition()
        #: the files waiting to be sent, in the order they were committed
        self._waiting: dict[str, None] = {}
        self._failures: dict[str, int] = {}
        self._busy = ""
        self._stopped = False
        self._store: Store | None = None
        self._thread: threading.Thread | None = None

    def start(self) -> None:
        self._thread = threading.Thread(target=self._run, name="workspace-push", daemon=True)
        self._thread.start()
        on_commit(self.committed)

    def stop(self) -> None:
        """Stop listening and sending (a push on its way is not waited for: what it did not
        send is sent by the next session's start)."""
        forget(self.committed)
        with self._cond:
            self._stopped = True
            self._cond.notify_all()

    def committed(self, path: Path) -> None:
        """A file is complete on disk (called by the writer, in its thread: returns at once)."""
        rel = relative_path(self.folder, path)
        if rel is None or any(part.startswith(".") for part in rel.split("/")):
            return
        with self._cond:
            self._waiting.pop(rel, None)
            self._waiting[rel] = None
            self._cond.notify_all()

    @property
    def waiting(self) -> list[str]:
        """The files not sent yet (the one being sent included)."""
        with self._cond:
            return ([self._busy] if self._busy else []) + [
                p for p in self._waiting if p != self._busy
            ]

    def wait_idle(self, timeout: float) -> bool:
        """Wait until nothing waits to be sent (True), or ``timeout`` seconds (False)."""
        with self._cond:
            return self._cond.wait_for(lambda: not self._waiting and not self._busy, timeout)

    def _run(self) -> None:
        delay = 0.0
        while True:
            with self._cond:
                if delay:
                    self._cond.wait_for(lambda: self._stopped, delay)
                    delay = 0.0
                idle = not self._cond.wait_for(self._ready, self.idle_close)
            if idle:
                self._close_store()
                continue
            with self._cond:
                if self._stopped:
                    break
                rel = next(iter(self._waiting))
                del self._waiting[rel]
                self._busy = rel
            failed = self._push(rel)
            with self._cond:
                self._busy = ""
                if failed:
                    self._waiting.setdefault(rel, None)
                self._cond.notify_all()
            tries = self._failures.get(rel, 0)
            delay = min(self.retry_most, self.retry_first * 2 ** (tries - 1)) if failed else 0.0
        self._close_store()

    def _close_store(self) -> None:
        """Give the connection back (after a while with nothing to send: a class's apps must
        not hold two connections each); the next send opens one again."""
        store, self._store = self._store, None
        if store is not None:
            with contextlib.suppress(Exception):
                store.close()

    def _ready(self) -> bool:
        return self._stopped or bool(self._waiting)

    def _push(self, rel: str) -> bool:
        """One try; True when it failed and is to be tried again."""
        try:
            if self._store is None:
                self._store = self.open_store()
            push_path(self._store, self.user, rel, self.folder, self.limits)
        except WorkspaceRefused as exc:
            self._failures.pop(rel, None)
            self._say(f"~/{rel} is kept on this server only: {exc}")
            return False
        except (StoreError, OSError) as exc:
            tries = self._failures[rel] = self._failures.get(rel, 0) + 1
            log.warning("workspace file %s of %s not sent (try %d): %s", rel, self.user, tries, exc)
            if tries == TELL_AFTER:
                self._say(
                    f"~/{rel} is not in the course store yet ({exc}); it is safe here and is "
                    "sent again"
                )
            return True
        if self._failures.pop(rel, 0) >= TELL_AFTER:
            self._say(f"~/{rel} is in the course store now")
        return False

    def _say(self, text: str) -> None:
        try:
            self.tell(text)
        except Exception:  # whoever listens is gone (the app ending)
            log.info("%s", text)


def sync_at_start(
    data_dir: str | os.PathLike, db: str, user: str, folder: str | os.PathLike
) -> SyncReport:
    """:func:`pull_workspace` with a store connection of its own, for a session about to
    start (in a thread: each call to the database may wait for its deadline). A database that
    cannot be reached, or refuses, is one problem in the report: the session starts with the
    files this server has."""
    try:
        with Store.open(data_dir, db=db) as store:
            report = pull_workspace(store, user, folder)
    except StoreError as exc:
        return SyncReport(problems=[f"the course store was not reached: {exc}"])
    except OSError as exc:
        return SyncReport(problems=[f"the workspace folder cannot be used: {exc}"])
    return report
