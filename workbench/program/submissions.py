"""The students' programs in a folder to grade, one :class:`~.grading.Submission` each.

Two layouts, mixed freely: a program file right in the folder is one student's program (the
student is the file's name without its ending), and a subfolder is one student's (the student
is the subfolder's name) holding exactly one program file. A program file is what the app runs:
``NAME.viple`` (VIPLE 3.5 and 4.x) or ``NAME.xml`` (VIPLE 3.x, gzip-compressed or plain), in
any case. A program's own key script is the file ``NAME.keys`` beside it (:mod:`.keyfiles`).

Nothing in the folder is passed over in silence: every file and folder that is not graded
(a hidden one, a file of another kind, a key script with no program beside it, a named pipe
or other special file) is a :class:`Skipped` with the reason. A special file is never opened
(reading a named pipe would wait for a writer).

The folder is the students' work, so everything in it is taken as hostile: a symbolic link,
a subfolder with no program or with several, a program too big to read or a bad key script
each becomes that student's refusal, never an error of the whole grading. Names are shown
with any character that is not printable as ``?``.
"""

from __future__ import annotations

import hashlib
import os
import stat
from dataclasses import dataclass, field
from pathlib import Path

from workbench.files.bidi import BIDI_CONTROLS
from workbench.files.bounded import BoundedFileError, read_bytes

from .grading import Submission
from .keyfiles import KEYS_SUFFIX, program_keys
from .keys import KeyScriptError
from .loader import LIMITS as PROGRAM_LIMITS
from .loader import PROGRAM_SUFFIXES, is_program_name

#: how the folder's messages name the program files it takes
PROGRAM_FILES = " or ".join(PROGRAM_SUFFIXES)
#: special files by kind (``lstat``: none of them is opened)
_SPECIAL = (
    (stat.S_ISFIFO, "a named pipe (FIFO)"),
    (stat.S_ISSOCK, "a socket"),
    (stat.S_ISCHR, "a character device"),
    (stat.S_ISBLK, "a block device"),
)


@dataclass(frozen=True)
class Skipped:
    """A file or folder of the hand-ins that is not graded: ``file`` as shown (relative to
    the folder) and why."""

    file: str
    reason: str


@dataclass
class HandIns:
    """What a folder holds: the submissions to grade and what was passed over."""

    submissions: list[Submission] = field(default_factory=list)
    skipped: list[Skipped] = field(default_factory=list)


class FolderError(ValueError):
    """The folder itself cannot be graded (missing, not a folder, unreadable)."""


def shown_name(name: str) -> str:
    """A file or folder name as the table shows it: undecodable bytes as U+FFFD, and
    characters that are not printable (or turn text around) as ``?``."""
    text = name.encode("utf-8", "surrogateescape").decode("utf-8", "replace")
    return "".join("?" if not c.isprintable() or BIDI_CONTROLS.match(c) else c for c in text)


def find_submissions(folder: str | os.PathLike, keys: str = "") -> list[Submission]:
    """Every student's program in ``folder`` (see :func:`scan_folder`)."""
    return scan_folder(folder, keys).submissions


def scan_folder(folder: str | os.PathLike, keys: str = "") -> HandIns:
    """Every student's program in ``folder``, ordered by student and file, and everything
    skipped, in the folder's order; ``keys`` is the key script of the programs that bring
    none of their own."""
    root = Path(folder)
    entries = _entries(root, folder)
    found = HandIns()
    names = {e.name for e in entries}
    for entry in entries:
        program = is_program(entry.name)
        student = shown_name(_stem(entry.name) if program else entry.name)
        if entry.name.startswith("."):
            found.skipped.append(_hidden(entry.name, entry))
        elif entry.is_symlink():
            if program or _is_dir(entry.path):
                found.submissions.append(
                    _refused(student, entry.name, "a symbolic link: hand in the file")
                )
            else:
                found.skipped.append(Skipped(shown_name(entry.name), "a symbolic link"))
        elif entry.is_dir():
            found.submissions.append(_from_subfolder(root, entry.name, keys, found.skipped))
        elif program and entry.is_file():
            found.submissions.append(_submission(root, student, entry.name, keys))
        elif (skip := _not_graded(entry.name, entry, names)) is not None:
            found.skipped.append(skip)
    found.submissions.sort(key=lambda s: (s.student, s.file))
    return found


def _entries(root: Path, folder: str | os.PathLike) -> list[os.DirEntry[str]]:
    try:
        return sorted(os.scandir(root), key=lambda e: e.name)
    except OSError as exc:
        raise FolderError(
            f"{folder}: cannot read the folder: {exc.strerror or type(exc).__name__}"
        ) from None


def is_program(name: str) -> bool:
    """A program's file name as the app takes it: ``NAME.viple`` or ``NAME.xml``, in any
    case (``NAME.VIPLE`` too)."""
    return is_program_name(name)


def _stem(name: str) -> str:
    return name.rsplit(".", 1)[0]


def _hidden(path: str, entry: os.DirEntry[str]) -> Skipped:
    what = "folder" if _is_dir(entry.path) and not entry.is_symlink() else "file"
    return Skipped(shown_name(path), f"a hidden {what} (its name starts with a dot)")


def _not_graded(path: str, entry: os.DirEntry[str], beside: set[str]) -> Skipped | None:
    """Why a file that is neither a folder nor a program to grade is passed over (None: it
    is the key script of a program beside it, which that program runs with)."""
    shown = shown_name(path)
    special = _special(entry)
    if special is not None:
        return Skipped(shown, f"{special}, not a plain file: never opened; hand in the file")
    name = entry.name
    if name.lower().endswith(KEYS_SUFFIX):
        stem = name[: -len(KEYS_SUFFIX)]
        if any(is_program(n) and _stem(n) == stem for n in beside):
            return None
        programs = " or ".join(stem + suffix for suffix in PROGRAM_SUFFIXES)
        return Skipped(shown, f"a key script with no program {programs} beside it")
    return Skipped(shown, f"not a VIPLE program (the app runs {PROGRAM_FILES} files)")


def _special(entry: os.DirEntry[str]) -> str | None:
    """What special file ``entry`` is (a named pipe, a socket, a device), None for a plain
    file; asked of the directory entry, never by opening it."""
    try:
        mode = entry.stat(follow_symlinks=False).st_mode
    except OSError:
        return "a file that cannot be examined"
    if stat.S_ISREG(mode):
        return None
    return next((what for test, what in _SPECIAL if test(mode)), "a special file")


def _is_dir(path: str) -> bool:
    try:
        return os.path.isdir(path)
    except OSError:
        return False


def _from_subfolder(root: Path, name: str, keys: str, skipped: list[Skipped]) -> Submission:
    student = shown_name(name)
    try:
        entries = sorted(os.scandir(root / name), key=lambda e: e.name)
    except OSError as exc:
        return _refused(student, name, f"cannot read the folder: {exc.strerror}")
    names = {e.name for e in entries}
    programs = []
    for entry in entries:
        path = f"{name}/{entry.name}"
        if entry.name.startswith("."):
            skipped.append(_hidden(path, entry))
        elif is_program(entry.name) and (entry.is_symlink() or _special(entry) is None):
            programs.append(entry)
        elif entry.is_dir(follow_symlinks=False):
            skipped.append(Skipped(shown_name(path), "a folder inside a student's folder"))
        elif (skip := _not_graded(path, entry, names)) is not None:
            skipped.append(skip)
    if not programs:
        return _refused(student, name, f"the folder holds no VIPLE program ({PROGRAM_FILES})")
    if len(programs) > 1:
        listed = ", ".join(shown_name(p.name) for p in programs[:5])
        return _refused(
            student,
            name,
            f"the folder holds {len(programs)} programs ({listed}): leave one to grade",
        )
    entry = programs[0]
    path = f"{name}/{entry.name}"
    if entry.is_symlink() or not entry.is_file(follow_symlinks=False):
        return _refused(student, path, "not a plain file (a symbolic link?): hand in the file")
    return _submission(root, student, path, keys)


def _submission(root: Path, student: str, path: str, keys: str) -> Submission:
    file = shown_name(path)
    try:
        data = read_bytes(root / path, PROGRAM_LIMITS, file)
    except BoundedFileError as exc:
        return Submission(student, file, path, refused=str(exc))
    sha256 = hashlib.sha256(data).hexdigest()
    try:
        script = program_keys(root / path, keys, source=file)
    except KeyScriptError as exc:
        return Submission(student, file, path, sha256, refused=f"key script: {exc}")
    return Submission(student, file, path, sha256, keys=script)


def _refused(student: str, path: str, reason: str) -> Submission:
    return Submission(student, shown_name(path), path, refused=reason)
