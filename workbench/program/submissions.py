"""The students' programs in a folder to grade, one :class:`~.grading.Submission` each.

Two layouts, mixed freely: a ``*.viple`` file right in the folder is one student's program
(the student is the file's name without ``.viple``), and a subfolder is one student's (the
student is the subfolder's name) holding exactly one ``*.viple`` file; ``.VIPLE`` counts too.
Files and folders whose names start with a dot, and files of other kinds, are passed over. A
program's own key script is the file ``NAME.keys`` beside it (:mod:`.keyfiles`).

The folder is the students' work, so everything in it is taken as hostile: a symbolic link,
a subfolder with no program or with several, a program too big to read or a bad key script
each becomes that student's refusal, never an error of the whole grading. Names are shown
with any character that is not printable as ``?``.
"""

from __future__ import annotations

import hashlib
import os
from pathlib import Path

from workbench.files.bidi import BIDI_CONTROLS
from workbench.files.bounded import BoundedFileError, read_bytes

from .grading import Submission
from .keyfiles import program_keys
from .keys import KeyScriptError
from .loader import LIMITS as PROGRAM_LIMITS

PROGRAM_SUFFIX = ".viple"


class FolderError(ValueError):
    """The folder itself cannot be graded (missing, not a folder, unreadable)."""


def shown_name(name: str) -> str:
    """A file or folder name as the table shows it: undecodable bytes as U+FFFD, and
    characters that are not printable (or turn text around) as ``?``."""
    text = name.encode("utf-8", "surrogateescape").decode("utf-8", "replace")
    return "".join("?" if not c.isprintable() or BIDI_CONTROLS.match(c) else c for c in text)


def find_submissions(folder: str | os.PathLike, keys: str = "") -> list[Submission]:
    """Every student's program in ``folder``, ordered by student and file; ``keys`` is the
    key script of the programs that bring none of their own."""
    root = Path(folder)
    try:
        entries = sorted(os.scandir(root), key=lambda e: e.name)
    except OSError as exc:
        raise FolderError(
            f"{folder}: cannot read the folder: {exc.strerror or type(exc).__name__}"
        ) from None
    found = []
    for entry in entries:
        if entry.name.startswith("."):
            continue
        program = is_program(entry.name)
        student = shown_name(entry.name[: -len(PROGRAM_SUFFIX)] if program else entry.name)
        if entry.is_symlink():
            if program or _is_dir(entry.path):
                found.append(_refused(student, entry.name, "a symbolic link: hand in the file"))
        elif entry.is_file() and program:
            found.append(_submission(root, student, entry.name, keys))
        elif entry.is_dir():
            found.append(_from_subfolder(root, entry.name, keys))
    return sorted(found, key=lambda s: (s.student, s.file))


def is_program(name: str) -> bool:
    """A program's file name: ``NAME.viple``, in any case (``NAME.VIPLE`` too)."""
    return name.lower().endswith(PROGRAM_SUFFIX) and len(name) > len(PROGRAM_SUFFIX)


def _is_dir(path: str) -> bool:
    try:
        return os.path.isdir(path)
    except OSError:
        return False


def _from_subfolder(root: Path, name: str, keys: str) -> Submission:
    student = shown_name(name)
    try:
        entries = sorted(os.scandir(root / name), key=lambda e: e.name)
    except OSError as exc:
        return _refused(student, name, f"cannot read the folder: {exc.strerror}")
    programs = [e.name for e in entries if is_program(e.name) and not e.name.startswith(".")]
    if not programs:
        return _refused(student, name, f"the folder holds no {PROGRAM_SUFFIX} program")
    if len(programs) > 1:
        listed = ", ".join(shown_name(p) for p in programs[:5])
        return _refused(
            student,
            name,
            f"the folder holds {len(programs)} programs ({listed}): leave one to grade",
        )
    entry = next(e for e in entries if e.name == programs[0])
    path = f"{name}/{entry.name}"
    if entry.is_symlink() or not entry.is_file():
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
