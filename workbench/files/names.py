"""Paths a client sends for a file in a workspace (an upload's name, a folder to list): which
are taken, and why the others are not.

The workspace is ``/``; a path names a place in it by its parts. A part that walks (``..``),
holds a control or bidi character, or is too long is refused with the reason, never resolved
or cleaned up into some other name.
"""

from __future__ import annotations

import unicodedata

from .bidi import bidi_problem

#: the longest name of one file or folder, and of a whole path, in bytes of UTF-8 (the limits
#: of the usual Linux file systems)
MAX_NAME_BYTES = 255
MAX_PATH_BYTES = 1024

#: where uploads are written until they are whole; never a name a client may use
UPLOADS_FOLDER = ".uploading"

Parts = tuple[str, ...]


class BadPath(ValueError):
    """A path that names no file a client may use; the message says why."""


def path_parts(raw: bytes | str) -> Parts:
    """The parts of a client's path inside the workspace (``()`` is the workspace itself).

    ``/`` and the empty path are the workspace; ``.`` parts and repeated slashes are skipped.
    """
    text = _decoded(raw)
    if len(text.encode()) > MAX_PATH_BYTES:
        raise BadPath(
            f"a path is at most {MAX_PATH_BYTES} bytes long (this one is "
            f"{len(text.encode())}): use shorter names or fewer folders"
        )
    parts = tuple(p for p in text.split("/") if p not in ("", "."))
    for part in parts:
        _check_part(part)
    return parts


def resolved_parts(raw: bytes | str) -> Parts:
    """``raw`` with ``..`` taken back one folder (never above the workspace): what a client's
    ``cd`` asks for, a name only; every other use of ``..`` is refused by :func:`path_parts`."""
    text = _decoded(raw)
    if len(text.encode()) > MAX_PATH_BYTES:
        return path_parts(text)  # refused with its reason
    parts: list[str] = []
    for part in text.split("/"):
        if part in ("", "."):
            continue
        if part == "..":
            if parts:
                parts.pop()
            continue
        parts.append(part)
    return path_parts("/".join(parts))


def shown_path(parts: Parts) -> str:
    """A path as a client and the log show it: ``/`` and then its parts."""
    return "/" + "/".join(parts)


def _decoded(raw: bytes | str) -> str:
    if isinstance(raw, str):
        return raw
    try:
        return raw.decode("utf-8")
    except UnicodeDecodeError:
        raise BadPath(
            "a file name must be UTF-8 text: rename the file on your computer with plain "
            "letters and try again"
        ) from None


def _check_part(part: str) -> None:
    if part == "..":
        raise BadPath(
            "'..' (the folder above) cannot be used in a path here: name the file from / "
            "(your workspace), e.g. /mazes/maze1.txt"
        )
    size = len(part.encode())
    if size > MAX_NAME_BYTES:
        raise BadPath(
            f"a file or folder name is at most {MAX_NAME_BYTES} bytes long (one here is "
            f"{size}, starting {part[:20]!r}): use a shorter name"
        )
    for i, char in enumerate(part):
        if unicodedata.category(char) == "Cc":
            raise BadPath(
                f"a name cannot hold control characters (U+{ord(char):04X} at position "
                f"{i + 1} of {part[:40]!r}): rename the file without them"
            )
    problem = bidi_problem(part, f"the name {part[:40]!r}")
    if problem:
        raise BadPath(f"{problem}: rename the file without it")
    if part == UPLOADS_FOLDER:
        raise BadPath(
            f"{UPLOADS_FOLDER} is where the server keeps uploads until they are whole: "
            "use another name"
        )
