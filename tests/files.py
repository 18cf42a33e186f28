"""Files a test writes into its own temporary folder."""

from __future__ import annotations

from pathlib import Path


def write(folder: Path, name: str, content: str | bytes) -> str:
    """``content`` (text, or bytes as they are) written to ``folder``/``name``; its path, as
    a command line takes it."""
    path = folder / name
    if isinstance(content, bytes):
        path.write_bytes(content)
    else:
        path.write_text(content)
    return str(path)
