"""Where a station's run records go, and how much room they may take.

Each run of a station with a record folder gets a record file there (``docs/run-record.md``).
Two limits keep one person's records from filling a disk: a cap on each record, and a quota on
the folder the records are counted in (a served student's ``~/runs``). A record that cannot be
written (the quota is spent, the disk is full, the folder's name is taken by a file) never ends
the run: the run goes on unrecorded and a :class:`RecordTrouble` says why; the next run tries
again, so recording comes back once there is room.
"""

from __future__ import annotations

import logging
import os
from dataclasses import dataclass
from pathlib import Path

from workbench.files.sizes import shown_size
from workbench.sim.record import DISK_FULL, NO_ROOM, Recorder, RecordStop

log = logging.getLogger("workbench.record")

#: the largest run record, and the most all run records in the counted folder may take
RECORD_CAP = 20_000_000
RUNS_QUOTA = 200_000_000
#: a run starts unrecorded when less than this is left of the quota
LEAST_ROOM = 64_000
#: entries looked at when the folder is counted: more and it counts as full
COUNT_LIMIT = 20_000

#: the kinds of :class:`RecordTrouble` besides the recorder's own (CAPPED, DISK_FULL, IO_ERROR)
QUOTA_FULL = "quota full"
TOO_MANY_FILES = "too many files"
MOVED_ASIDE = "moved aside"
NO_FOLDER = "no folder"


@dataclass(frozen=True)
class RecordQuota:
    """How much room run records may take (None: no limit)."""

    #: bytes one record may grow to
    record: int | None = RECORD_CAP
    #: bytes all files under :attr:`folder` may take together
    runs: int | None = RUNS_QUOTA
    #: the folder counted against :attr:`runs` (a served student's ``~/runs``); None: the
    #: station's own record folder
    folder: str | None = None


@dataclass(frozen=True)
class RecordTrouble:
    """Why a run is (or went on) unrecorded, or what was done to record it."""

    #: CAPPED, DISK_FULL, IO_ERROR (the record stopped mid-run), QUOTA_FULL, TOO_MANY_FILES,
    #: NO_FOLDER (the run is not recorded) or MOVED_ASIDE (recorded, after moving a file)
    kind: str
    #: the record, the counted folder, or the file moved aside
    path: str
    #: the limit in bytes (CAPPED, QUOTA_FULL), the system's words for an error (DISK_FULL,
    #: IO_ERROR, NO_FOLDER) or where the file went (MOVED_ASIDE)
    detail: str = ""


def record_stopped(path: str, stop: RecordStop) -> RecordTrouble:
    """A record that stopped mid-run (its cap, a full disk): logged, and said as trouble."""
    log.warning("run record stopped at t=%.2f: %s: %s (%s)", stop.t, path, stop.reason, stop.detail)
    return RecordTrouble(stop.reason, path, stop.detail)


def folder_usage(folder: str | os.PathLike, limit: int = COUNT_LIMIT) -> int | None:
    """Bytes of the regular files under ``folder`` (0 when it does not exist), or None when
    it holds more than ``limit`` entries (never following links)."""
    total, seen = 0, 0
    pending = [os.fspath(folder)]
    while pending:
        try:
            entries = list(os.scandir(pending.pop()))
        except (FileNotFoundError, NotADirectoryError):
            continue
        except OSError:
            return None
        for entry in entries:
            seen += 1
            if seen > limit:
                return None
            try:
                if entry.is_dir(follow_symlinks=False):
                    pending.append(entry.path)
                elif entry.is_file(follow_symlinks=False):
                    total += entry.stat(follow_symlinks=False).st_size
            except OSError:
                continue
    return total


def _make_folder(folder: Path, workspace: Path | None) -> RecordTrouble | None:
    """Make the record folder; a file of the student's in its way (inside the workspace) is
    renamed ``NAME.taken-N`` (MOVED_ASIDE). The folder is there unless another trouble says
    why not."""
    try:
        folder.mkdir(parents=True, exist_ok=True)
        return None
    except (FileExistsError, NotADirectoryError) as exc:
        blocker = _first_non_folder(folder)
        if blocker is None or workspace is None or not _strictly_inside(blocker, workspace):
            return RecordTrouble(NO_FOLDER, str(folder), _words(exc))
        aside = _free_name(blocker)
        try:
            blocker.rename(aside)
            folder.mkdir(parents=True, exist_ok=True)
        except OSError as again:
            return RecordTrouble(NO_FOLDER, str(folder), _words(again))
        log.warning("run records: %s was a file in the way: moved to %s", blocker, aside)
        return RecordTrouble(MOVED_ASIDE, str(blocker), str(aside))
    except OSError as exc:
        return RecordTrouble(_kind(exc), str(folder), _words(exc))


def _first_non_folder(folder: Path) -> Path | None:
    """The nearest of ``folder`` and its parents that exists and is not a folder."""
    for path in (folder, *folder.parents):
        if path.is_symlink() or path.exists():
            return None if path.is_dir() and not path.is_symlink() else path
    return None


def _strictly_inside(path: Path, folder: Path) -> bool:
    return path != folder and path.is_relative_to(folder)


def _free_name(path: Path) -> Path:
    n = 1
    while (aside := path.with_name(f"{path.name}.taken-{n}")).exists() or aside.is_symlink():
        n += 1
    return aside


def _kind(exc: OSError) -> str:
    return DISK_FULL if exc.errno in NO_ROOM else NO_FOLDER


def _words(exc: OSError) -> str:
    return exc.strerror or str(exc)


def open_record(
    folder: str,
    name: str,
    quota: RecordQuota,
    workspace: Path | None = None,
) -> tuple[Recorder | None, RecordTrouble | None]:
    """A recorder for the run record ``folder/name`` within ``quota`` (None when the run goes
    unrecorded), and what stood in the way, if anything."""
    path = Path(folder)
    trouble = _make_folder(path, workspace)
    if trouble is not None and trouble.kind != MOVED_ASIDE:
        log.warning("run not recorded: %s: %s (%s)", trouble.path, trouble.kind, trouble.detail)
        return None, trouble
    cap = quota.record
    if quota.runs is not None:
        counted = quota.folder or folder
        used = folder_usage(counted)
        if used is None or quota.runs - used < LEAST_ROOM:
            kind = TOO_MANY_FILES if used is None else QUOTA_FULL
            log.warning(
                "run not recorded: %s holds %s of its quota of %s",
                counted,
                "too many files" if used is None else shown_size(used),
                shown_size(quota.runs),
            )
            return None, RecordTrouble(kind, counted, str(quota.runs))
        cap = quota.runs - used if cap is None else min(cap, quota.runs - used)
    try:
        recorder = Recorder(path / name, cap=cap, keep_going=True)
    except OSError as exc:
        log.warning("run not recorded: %s: %s", path / name, _words(exc))
        return None, RecordTrouble(_kind(exc), str(path / name), _words(exc))
    return recorder, trouble
