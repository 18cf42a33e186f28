"""Key scripts kept in files: the one given for every program (``--keys-file``) and a
program's own, the file ``NAME.keys`` beside ``NAME.viple``.

A key script file holds the same text as ``--keys`` (``w@0.5 release@3``, see
:mod:`.keys`), over as many lines as it likes. It is read with the limits on input files and
checked before anything runs, so a bad script is named with its file and the item at fault.
"""

from __future__ import annotations

import os
from pathlib import Path

from workbench.files.bounded import BoundedFileError, Limits, read_text

from .keys import KeyScriptError, parse_key_script

KEYS_SUFFIX = ".keys"
KEY_FILE_LIMITS = Limits("a key script", max_bytes=256 << 10, max_lines=20_000)


def read_key_file(path: str | os.PathLike, source: str | None = None) -> str:
    """The key script in ``path``, checked; :class:`KeyScriptError` names the file and what
    is wrong (it cannot be read, or an item is not ``KEY@SECONDS``)."""
    source = str(path) if source is None else source
    try:
        text = read_text(path, KEY_FILE_LIMITS, source)
    except BoundedFileError as exc:
        raise KeyScriptError(str(exc)) from None
    script = " ".join(text.split())
    try:
        parse_key_script(script)
    except KeyScriptError as exc:
        raise KeyScriptError(f"{source}: {exc}") from None
    return script


def own_key_file(program: str | os.PathLike) -> Path:
    """Where a program's own key script is kept: ``NAME.keys`` beside ``NAME.viple``."""
    path = Path(program)
    return path.with_name(path.stem + KEYS_SUFFIX)


def program_keys(program: str | os.PathLike, default: str = "", source: str | None = None) -> str:
    """The key script a program runs with: its own file's (see :func:`own_key_file`; a
    symbolic link there is refused) when there is one, else ``default``. ``source`` is how
    the program's path is shown in messages."""
    own = own_key_file(program)
    if not os.path.lexists(own):
        return default
    shown = str(own_key_file(source)) if source is not None else str(own)
    if os.path.islink(own):
        raise KeyScriptError(f"{shown}: a symbolic link: keep the key script itself there")
    return read_key_file(own, shown)
