"""What the message line says when a run goes (or went on) unrecorded."""

from __future__ import annotations

import os
from collections.abc import Callable

from workbench.control.recording import (
    MOVED_ASIDE,
    NO_FOLDER,
    QUOTA_FULL,
    TOO_MANY_FILES,
    RecordTrouble,
    shown_size,
)
from workbench.sim.record import CAPPED, DISK_FULL, TOO_FAST

#: the run goes on; what brings recording back
_NEXT = "the next run (r resets the robot) is recorded again"


def record_words(trouble: RecordTrouble, shown: Callable[[str | os.PathLike], str]) -> str:
    """The trouble in words; ``shown`` gives a path as the person sees it (``~/runs``)."""
    where = shown(trouble.path)
    if trouble.kind == CAPPED:
        return (
            f"recording stopped: {where} reached its size limit of "
            f"{shown_size(int(trouble.detail))}; the run goes on unrecorded, {_NEXT}"
        )
    if trouble.kind == TOO_FAST:
        return (
            f"recording stopped: {where} grew by more than {shown_size(int(trouble.detail))} "
            f"in one simulated second; the run goes on unrecorded, {_NEXT}"
        )
    if trouble.kind == DISK_FULL:
        return (
            f"recording stopped: no room on the disk for {where} ({trouble.detail}); the run "
            f"goes on unrecorded, and {_NEXT} once there is room"
        )
    if trouble.kind == QUOTA_FULL:
        return (
            f"this run is not recorded: your run records in {where} already take their "
            f"{shown_size(int(trouble.detail))}; the run goes on (ask your instructor to "
            "clear old run records)"
        )
    if trouble.kind == TOO_MANY_FILES:
        return (
            f"this run is not recorded: {where} holds too many files to count; the run goes "
            "on (ask your instructor to clear old run records)"
        )
    if trouble.kind == MOVED_ASIDE:
        return (
            f"your file {where} was in the way of your run records: it is now "
            f"{shown(trouble.detail)}, and this run is recorded"
        )
    if trouble.kind == NO_FOLDER:
        return (
            f"this run is not recorded: cannot make the folder {where} ({trouble.detail}); "
            "the run goes on"
        )
    return (
        f"recording stopped: cannot write {where} ({trouble.detail}); the run goes on "
        f"unrecorded, {_NEXT}"
    )
