"""Saving a picture of runs from a screen: drawn in a thread worker (matplotlib is slow to
load and a large run takes a second or two), the screen told before and after.

The drawing and the saving are the core's (``pictures/saving.py``); this only runs it off the
event loop and words what happened.
"""

from __future__ import annotations

import os
from collections.abc import Callable, Sequence

from textual.screen import Screen

from workbench.files.workspace import FileAccess
from workbench.sim.maze import Maze

#: how a screen shows a line: the text, and whether it is an error
Say = Callable[[str, bool], None]

#: what each kind of picture is called in the messages
KIND_WORDS = {"path": "path", "time": "plot over time", "compare": "side-by-side picture"}


def saved_words(what: str, shown: str, size: int, confined: bool) -> str:
    where = f"saved the {what} in {shown} ({size:,} bytes)"
    if confined:
        return f"{where}: download it with sftp or scp (get {shown.removeprefix('~/')})"
    return where


def save_picture_off_the_loop(
    screen: Screen,
    records: Sequence[str | os.PathLike],
    kind: str,
    files: FileAccess,
    say: Say,
    *,
    what: str,
    at: Sequence[float] = (),
    known: Sequence[Maze] = (),
) -> None:
    """Draw and save the picture in a thread; ``say`` tells the screen (on its loop). One
    picture at a time per screen: a key pressed while one is drawn is answered, not queued."""
    if any(w.group == "picture" and w.node is screen and not w.is_finished for w in screen.workers):
        say("a picture is being drawn: wait for it to be saved, then ask again", True)
        return
    words = f"{KIND_WORDS[kind]} of {what}"
    say(f"drawing the {words}...", False)
    app = screen.app

    def work() -> None:
        from workbench.pictures.runs import PictureError
        from workbench.pictures.saving import save_in_workspace

        try:
            saved = save_in_workspace(records, kind, files, at=at, known=known)
        except PictureError as exc:
            app.call_from_thread(say, f"no picture: {exc}", True)
            return
        except (OSError, MemoryError, ValueError) as exc:
            app.call_from_thread(say, f"no picture: the drawing failed ({exc})", True)
            return
        app.call_from_thread(
            say, saved_words(f"{words}", saved.shown, saved.size, files.confined), False
        )

    screen.run_worker(work, thread=True, group="picture", exit_on_error=False)
