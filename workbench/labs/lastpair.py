"""Who was at this workbench last: the pair of names the app offers when it starts.

Kept in the data folder as ``last-pair.json`` (``{"student": ..., "partner": ...}``). A file
that is missing, too big, not JSON or holds names the workbench would refuse is ignored: the
names are a convenience, never a reason not to start. Only a workbench used by one person at a
time keeps it; a served (SSH) session never reads or writes it, since the data folder there is
the server's.
"""

from __future__ import annotations

import json
import os
from pathlib import Path

from workbench.files.atomic import write_text_atomic
from workbench.files.private import PRIVATE_FILE, private_dir

from .names import NameProblem, check_pair

FILE_NAME = "last-pair.json"
#: far more than two names of 40 characters need
MAX_BYTES = 4096


def read_last_pair(data_dir: str | os.PathLike) -> tuple[str, str] | None:
    """The pair saved last in ``data_dir`` (None when there is none that can be used)."""
    path = Path(data_dir) / FILE_NAME
    try:
        with path.open("rb") as f:
            data = f.read(MAX_BYTES + 1)
        if len(data) > MAX_BYTES:
            return None
        saved = json.loads(data.decode("utf-8"))
        return check_pair(str(saved["student"]), str(saved.get("partner", "")))
    except (OSError, ValueError, KeyError, TypeError, NameProblem):
        return None


def save_last_pair(data_dir: str | os.PathLike, student: str, partner: str = "") -> None:
    """Remember the pair at this workbench (written whole, then moved into place)."""
    folder = Path(data_dir)
    private_dir(folder)
    path = folder / FILE_NAME
    write_text_atomic(
        path, json.dumps({"student": student, "partner": partner}), mode=PRIVATE_FILE
    )
