"""The instructor's console as an app of its own: ``workbench instructor console`` on the
instructor's machine, and the app a lab server runs for an SSH account whose role is
instructor (instead of a student's workbench).

It holds no robot: only the course store, the labs (for the exercises' titles) and the
console's screens. The instructor's signing key is unlocked in this process, with the
passphrase typed here.
"""

from __future__ import annotations

from typing import ClassVar

from textual.binding import BindingType

from workbench.labs.course_store import Store, StoreError, open_to_read
from workbench.labs.model import Lab, LabFileError, load_labs
from workbench.wire.settings import AppSettings

from .app import FOCUS_BINDINGS
from .host import ScreenHost
from .keys import APP_KEY_IDS, bindings
from .screens.console import ConsoleScreen


class ConsoleApp(ScreenHost[None]):
    """The class, its sign-off queue, and signing off from here."""

    TITLE = "VIPLE Maze Lab Workbench: instructor's console"
    BINDINGS: ClassVar[list[BindingType]] = [
        *(b for b in bindings(*APP_KEY_IDS) if b.action == "quit"),
        *FOCUS_BINDINGS,
    ]

    def __init__(
        self, store: Store, labs: list[Lab], *, instructor: str = "", unicode: bool = False
    ) -> None:
        super().__init__()
        self.store = store
        self.labs = labs
        self.instructor = instructor
        self.unicode = unicode
        self.console_screen: ConsoleScreen | None = None

    def on_mount(self) -> None:
        super().on_mount()
        self.console_screen = ConsoleScreen(self.store, self.labs, self.instructor)
        self.push_screen(self.console_screen)

    def on_unmount(self) -> None:
        self.store.close()


def make_console(settings: AppSettings) -> ConsoleApp:
    """The console on the store the settings name (a course database, or the SQLite file in
    the data folder); :class:`StoreError` when it cannot be opened, :class:`LabFileError`
    when a lab file is broken."""
    store = open_to_read(settings.data_dir, settings.db)
    try:
        labs = load_labs()
    except LabFileError:
        store.close()
        raise
    login = settings.student or ""
    return ConsoleApp(store, labs, instructor=login, unicode=settings.unicode)


__all__ = ["ConsoleApp", "StoreError", "make_console"]
