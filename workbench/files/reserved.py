"""The folders of a workspace that only the workbench writes: the run records its recorder
keeps in ``~/runs``. The one write rule every writer of a workspace keeps (the app's saves,
:mod:`.workspace`; the file server, :mod:`.workspace_files`)."""

from __future__ import annotations

#: the folders the app keeps in a workspace (its run records): never a student's file's name
RESERVED = ("runs",)


def reserved_problem(parts: tuple[str, ...]) -> str:
    """Why the workspace path ``parts`` (``("runs", "run-003.jsonl")``) may not be written by
    anyone but the workbench's run recorder, or ``""`` when it may be, in words that follow
    the path as it is shown."""
    if not parts or parts[0] not in RESERVED:
        return ""
    if len(parts) == 1:
        return (
            "is the folder the workbench keeps your run records in: save under another name, "
            f"e.g. ~/{parts[0]}-maze.txt"
        )
    return (
        f"is inside ~/{parts[0]}, where the workbench keeps your run records: they can be "
        f"read, replayed and copied, never changed; save under another name, e.g. "
        f"~/{parts[-1]}"
    )
