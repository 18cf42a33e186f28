"""Writes the course database did not get yet, kept in a file of the data folder so that they
outlive the app: the store writes the file each time it keeps a write pending, and a later
app of the same student reads it back and saves what it holds once the database answers.

One file per student (``pending/<digest of the name>.json``; a served lab's data folder is
shared by all its students), written whole to a new file that then replaces the old one, so a
crash leaves the old file or the new one. The file holds data, never SQL: each entry is the
kind of write (``progress``, ``place``, ``driver``) and its values, checked when read (the
entry must be the file's student's, of a known kind, with the right number of text values and,
for progress, a JSON object), and an entry that does not pass is left out and named.
"""

from __future__ import annotations

import contextlib
import hashlib
import json
import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from workbench.files.atomic import write_text_atomic
from workbench.files.bounded import Limits, read_text
from workbench.files.private import PRIVATE_FILE, private_dir

#: the values of each kind of write, in the order of its statement
FIELDS = {
    "progress": ("student", "lab", "exercise", "progress", "updated_at"),
    "place": ("student", "lab", "exercise", "updated_at"),
    "driver": ("student", "partner", "lab", "exercise", "driver", "updated_at"),
}
#: which values make the write's key (a newer write of the same key replaces an older one)
KEY_FIELDS = {
    "progress": ("student", "lab", "exercise"),
    "place": ("student",),
    "driver": ("student", "partner", "lab", "exercise"),
}
LIMITS = Limits("a file of pending writes", max_bytes=4 << 20, max_lines=400_000,
                max_line_length=200_000)  # fmt: skip
FORMAT = "workbench pending writes 1"


@dataclass(frozen=True)
class PendingWrite:
    kind: str
    values: tuple[str, ...]

    @property
    def key(self) -> tuple[str, ...]:
        named = dict(zip(FIELDS[self.kind], self.values, strict=True))
        return (self.kind, *(named[k] for k in KEY_FIELDS[self.kind]))


def pending_path(data_dir: str | os.PathLike, student: str) -> Path:
    """The file of ``student``'s pending writes in the data folder."""
    digest = hashlib.sha256(student.encode()).hexdigest()[:24]
    return Path(data_dir) / "pending" / f"{digest}.json"


def save_pending(path: Path, student: str, writes: list[PendingWrite]) -> None:
    """Write the file (or remove it when nothing is pending). OSError if it cannot be."""
    if not writes:
        with contextlib.suppress(FileNotFoundError):
            path.unlink()
        return
    private_dir(path.parent)
    data = {
        "format": FORMAT,
        "student": student,
        "writes": [{"kind": w.kind, "values": list(w.values)} for w in writes],
    }
    write_text_atomic(path, json.dumps(data, ensure_ascii=False, indent=1), mode=PRIVATE_FILE)


def load_pending(path: Path, student: str) -> tuple[list[PendingWrite], list[str]]:
    """The writes kept in the file for ``student`` (none when there is no file), and what was
    left out of it and why."""
    if not path.is_file():
        return [], []
    try:
        data = json.loads(read_text(path, LIMITS))
    except (OSError, ValueError) as exc:
        return [], [f"{path}: not a file of pending writes ({exc}); nothing taken from it"]
    if not isinstance(data, dict) or data.get("format") != FORMAT:
        return [], [f"{path}: not a file of pending writes; nothing taken from it"]
    if data.get("student") != student:
        return [], [f"{path}: the pending writes of someone else; nothing taken from it"]
    writes: list[PendingWrite] = []
    problems: list[str] = []
    entries = data.get("writes")
    for n, entry in enumerate(entries if isinstance(entries, list) else [], 1):
        problem = _problem(entry, student)
        if problem:
            problems.append(f"{path}: write {n} left out: {problem}")
            continue
        writes.append(PendingWrite(entry["kind"], tuple(entry["values"])))
    return writes, problems


def _problem(entry: Any, student: str) -> str:
    if not isinstance(entry, dict) or entry.get("kind") not in FIELDS:
        return "not a known kind of write"
    kind = entry["kind"]
    values = entry.get("values")
    fields = FIELDS[kind]
    if not isinstance(values, list) or len(values) != len(fields):
        return f"a {kind} write needs {len(fields)} values ({', '.join(fields)})"
    if not all(isinstance(v, str) for v in values):
        return "its values must be text"
    if values[0] != student:
        return "it is another student's"
    if kind == "progress":
        try:
            progress = json.loads(values[3])
        except ValueError:
            progress = None
        if not isinstance(progress, dict):
            return "its progress is not a JSON object"
    return ""
