"""Sizes as people write and read them: ``20M``, ``500k``, ``1.5G`` (decimal units, as disks
are sold) in options, and ``20 MB`` in messages."""

from __future__ import annotations

import re

_SIZE = re.compile(r"(\d+(?:\.\d+)?)\s*([kmg]?)b?", re.IGNORECASE)
_UNITS = {"": 1, "k": 1_000, "m": 1_000_000, "g": 1_000_000_000}


def parse_size(text: str) -> int:
    """``20M``, ``500k``, ``1.5G`` or a number of bytes; ValueError says what is accepted."""
    match = _SIZE.fullmatch(text.strip())
    if match is None:
        raise ValueError(
            f"{text!r} is not a size: give bytes or a number with k, M or G (e.g. 20M)"
        )
    return int(float(match.group(1)) * _UNITS[match.group(2).lower()])


def shown_size(size: int) -> str:
    """A size as people say it: ``20 MB``, ``500 kB``."""
    for unit, name in ((1_000_000_000, "GB"), (1_000_000, "MB"), (1_000, "kB")):
        if size >= unit:
            return f"{size / unit:.3g} {name}"
    return f"{size} bytes"
