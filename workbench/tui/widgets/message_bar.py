"""One line for what the workbench has to say (run finished, errors, hints) and who is in.

With nothing to say it names the app's keys: under a dialog only those that reach the app past
it (the help's ``?`` does not)."""

from __future__ import annotations

from textual.reactive import var
from textual.widgets import Static

from .under_dialog import DialogWatch

#: the keys the line names when it has nothing to say
APP_KEYS = "? help  ctrl+p commands  ctrl+q quit"
#: the same while a dialog is open over the screen
APP_KEYS_UNDER_DIALOG = "ctrl+p commands  ctrl+q quit"


class MessageBar(Static):
    """The workbench's message on the left; the user and role on the right."""

    DEFAULT_CSS = """
    MessageBar {
        height: auto;
        max-height: 8;
        padding: 0 1;
        background: $boost;
        color: $text-muted;
    }
    MessageBar.-message {
        color: $text-warning;
    }
    """

    message: var[str] = var("")
    who: var[str] = var("")

    def __init__(self, who: str = "", *, id: str | None = None, classes: str | None = None):
        super().__init__(id=id, classes=classes, markup=False)
        self.set_reactive(MessageBar.who, who)
        #: the text took more than one row when last painted
        self._wrapped = False
        self._under = DialogWatch(self, self._paint)

    def on_mount(self) -> None:
        self._under.start()
        self._paint()

    def on_unmount(self) -> None:
        self._under.stop()

    def watch_message(self) -> None:
        self._paint()

    def watch_who(self) -> None:
        self._paint()

    def _paint(self) -> None:
        self.set_class(bool(self.message), "-message")
        text = self.message or (APP_KEYS if self._under.dialog is None else APP_KEYS_UNDER_DIALOG)
        who = self.who
        width = max(self.size.width - 2, 0)
        if who and width and len(text) + len(who) + 2 <= width:
            text = text + " " * (width - len(text) - len(who)) + who
        wrapped = bool(width) and len(text) > width
        # a one-row text repaints in place (the common case, many times a second); a text
        # that wraps, or one that wrapped before, makes the bar take the rows it needs
        self.update(text, layout=wrapped or self._wrapped)
        self._wrapped = wrapped

    def on_resize(self) -> None:
        self._paint()
