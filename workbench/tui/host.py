"""How screens and the app that hosts them speak to each other.

A screen never reaches into the app: it posts one of the messages below, which bubbles up to
the app. The app speaks to its screens only through the small roles a screen may take on:
:class:`ShowsSnapshot` (draws the station at each tick), :class:`ShowsStatus` (shows the
workbench's one-line message, who is at the robot and the VIPLE connection line) and
:class:`FollowsUnicode` (redraws when the drawing switches between Unicode and ASCII).
:class:`ScreenHost` is the part of an app that every host shares, the workbench app and the
tests' bare hosts alike: it holds the Unicode setting, toggles it when a screen asks and applies
it to every screen, and hands what is said (:class:`Say`) to every screen that shows it. The
words are the TUI's: the station below only holds values.
"""

from __future__ import annotations

import os
from typing import TYPE_CHECKING, Literal, TypeVar

from textual.app import App
from textual.binding import Binding
from textual.message import Message
from textual.reactive import var

from workbench.labs.model import Setup
from workbench.sim.session import Snapshot

from .plain import PlainCommandPalette, follow

ReturnType = TypeVar("ReturnType")
#: the screens a screen may ask the app to open
ScreenName = Literal["editor", "runs", "labs", "main", "fsm"]


class ShowsSnapshot:
    """A screen that draws the station: the app hands it every snapshot it draws.

    A role, not a base: the screen defines ``show_snapshot`` itself (a mixin with an abstract
    method would clash with Textual's metaclass).
    """

    if TYPE_CHECKING:

        def show_snapshot(self, snapshot: Snapshot) -> None: ...


class ShowsStatus:
    """A screen with the workbench's message line: the app hands it what is said, the VIPLE
    endpoints' status and who is at the robot (it defines ``show_message``,
    ``show_connection`` and ``show_who``)."""

    if TYPE_CHECKING:

        def show_message(self, text: str) -> None: ...

        def show_connection(self, text: str) -> None: ...

        def show_who(self, who: str) -> None: ...


class FollowsUnicode:
    """A screen that draws in Unicode or ASCII as the app's setting says (it defines
    ``set_unicode``)."""

    if TYPE_CHECKING:

        def set_unicode(self, unicode: bool) -> None: ...


class TakesAllKeys:
    """A screen that may, for a while, take every key itself (the main screen while all keys
    go to a running program): the app then answers only its quit key (``takes_all_keys``)."""

    if TYPE_CHECKING:

        @property
        def takes_all_keys(self) -> bool: ...


class ToggleUnicode(Message):
    """Switch the drawing between Unicode and ASCII, on every screen."""


class Say(Message):
    """Put ``text`` on the workbench's message line ("" clears it)."""

    def __init__(self, text: str) -> None:
        super().__init__()
        self.text = text


class StationChanged(Message):
    """An action changed the station: every screen that shows it redraws."""


class MazeChanged(Message):
    """The station has a new maze (or profile); ``path`` is its file when it came from one."""

    def __init__(self, path: str | os.PathLike | None = None) -> None:
        super().__init__()
        self.path = path


class SetUpDone(Message):
    """A lab exercise's set-up changed the station (maze, profile, sensors, driver)."""

    def __init__(self, setup: Setup) -> None:
        super().__init__()
        self.setup = setup


class OpenScreen(Message):
    """Open one of the app's screens over the current one (``path``: the file it opens, for
    the FSM editor; "" its own choice)."""

    def __init__(self, screen: ScreenName, path: str = "") -> None:
        super().__init__()
        self.screen = screen
        self.path = path


class StartEndpoint(Message):
    """Start the app's VIPLE endpoint of ``role`` (``tcp`` or ``ws``)."""

    def __init__(self, role: str) -> None:
        super().__init__()
        self.role = role


class ScreenHost(App[ReturnType]):
    """The Unicode setting of an app that hosts the workbench's screens, in one place."""

    # ASCII mode: Textual's own widgets and the side rules of the screens every host may open
    # (the replay, the editor) without block-element borders (plain.py replaces their
    # glyphs); here rather than in the app's stylesheet, so every host has them. Not scoped:
    # Textual would scope these rules to the app's descendants, and the app is not its own
    # descendant, so only the first selector of each list would match.
    SCOPED_CSS = False
    DEFAULT_CSS = """
    App.-ascii OptionList,
    App.-ascii OptionList:focus {
        border: ascii $border-blurred;
    }
    App.-ascii #alg-builtins,
    App.-ascii #alg-builtins:focus {
        border: none;
    }
    App.-ascii CommandPalette #--input,
    App.-ascii CommandPalette LoadingIndicator {
        border: none;
        border-bottom: ascii $border;
    }
    App.-ascii #editor-side,
    App.-ascii #replay-side {
        border-left: ascii $panel;
    }
    App.-ascii CommandPalette CommandList,
    App.-ascii CommandPalette CommandList:focus {
        border: none;
        border-bottom: ascii $border;
    }
    """

    #: draw with Unicode lines, arrows and marks (False: plain ASCII)
    unicode: var[bool] = var(False, init=False)

    def on_mount(self) -> None:
        self.mark_ascii()

    def on_toggle_unicode(self, message: ToggleUnicode) -> None:
        self.unicode = not self.unicode

    def on_say(self, message: Say) -> None:
        self.say(message.text)

    def say(self, text: str) -> None:
        """Show ``text`` on the message line of every screen that has one."""
        for screen in self.screen_stack:
            if isinstance(screen, ShowsStatus):
                screen.show_message(text)

    def watch_unicode(self, unicode: bool) -> None:
        self.mark_ascii()
        for screen in self.screen_stack:
            follow(screen, unicode)
            if isinstance(screen, FollowsUnicode):
                screen.set_unicode(unicode)

    def mark_ascii(self, update: bool = True) -> None:
        """The app's CSS class for plain-ASCII drawing (panel borders and frames, scroll bars,
        the glyphs of Textual's own widgets: see :mod:`workbench.tui.plain`); ``update=False``
        before the app runs, so the first styling of every widget has it already."""
        self.set_class(not self.unicode, "-ascii", update=update)

    def get_key_display(self, binding: Binding) -> str:
        """A key as the footer shows it; in ASCII mode arrows are named (``right``, not ``→``)."""
        text = super().get_key_display(binding)
        if self.unicode or text.isascii():
            return text
        return binding.key.split(",")[0].strip()

    def action_command_palette(self) -> None:
        """The command palette; in ASCII mode without its emoji search icon."""
        if self.unicode:
            super().action_command_palette()
        # is_open asks for an App[object], which no App[ReturnType] is (App is invariant)
        elif self.use_command_palette and not PlainCommandPalette.is_open(self):  # type: ignore[arg-type]
            self.push_screen(PlainCommandPalette())
