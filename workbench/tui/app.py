"""The workbench app: one station (maze, robot, driver, runs) behind a Textual front end.

:func:`make_app` builds the app for the command line, the SSH server and the tests. The app
ticks the simulation from a Textual interval: each tick hands the real time that has passed to
the station (a fixed-step accumulator, so a late tick loses no simulated time), then draws one
snapshot on every screen that shows it.
"""

from __future__ import annotations

import asyncio
import contextlib
import gc
import getpass
import math
import os
import sys
from collections.abc import Callable
from dataclasses import replace
from functools import partial
from pathlib import Path
from time import perf_counter
from typing import ClassVar

from textual import events
from textual.binding import Binding, BindingType
from textual.screen import ModalScreen, Screen

from workbench.control.station import LabStation
from workbench.files.bundled import default_maze_path
from workbench.files.workspace import LOCAL, FileAccess
from workbench.labs.course_store import (
    CourseStore,
    KeptNotSaved,
    KeptSaved,
    Opened,
    Store,
    StoreEvent,
    WorkspacePusher,
    resolve_data_dir,
)
from workbench.labs.lastpair import read_last_pair, save_last_pair
from workbench.labs.model import Setup
from workbench.labs.names import NameProblem, check_pair
from workbench.sim.maze import Maze, MazeError
from workbench.sim.mazeio import load_maze
from workbench.sim.noise import NOISE_LEVELS
from workbench.sim.profiles import PROFILES, check_report_ms
from workbench.viple.hosting import Endpoints
from workbench.viple.tcp_server import TcpConfig
from workbench.viple.ws_client import WsConfig
from workbench.wire.settings import AppSettings

from .commands import WorkbenchCommands
from .dialogs.help import HelpScreen
from .dialogs.too_small import TooSmallScreen
from .host import (
    MazeChanged,
    OpenScreen,
    ScreenHost,
    ScreenName,
    SetUpDone,
    ShowsSnapshot,
    ShowsStatus,
    StartEndpoint,
    StationChanged,
    TakesAllKeys,
)
from .keys import APP_KEY_IDS, bindings
from .screens.arrival import ArrivalScreen
from .screens.editor import EditorScreen
from .screens.fsm_editor import FsmEditorScreen
from .screens.labs import LabsScreen, StoreNews
from .screens.main import MainScreen
from .screens.runs import RunsScreen
from .serving import warmup
from .serving.loop_clock import LoopClock
from .serving.ordered_keys import OrderedKeys
from .serving.quick_keys import QuickKeys, as_key_press
from .serving.seat import Seat
from .serving.terminal_driver import serves
from .textual_private import end_with_error, handled_size

#: the smallest terminal the layout is made for (columns, rows)
MIN_SIZE = (80, 24)
#: how long quitting waits for the course database to take what is pending (it is in the
#: pending file already, for the next app, if it does not)
STORE_LAST_TRY_SECONDS = 2.0
#: how often the clock ticks while the station is at rest (paused, or the robot standing with
#: nobody driving it): time passes as before, in larger steps, and nothing else needs drawing
REST_HZ = 0.25
ROLES = ("student", "instructor")


#: tab and shift+tab move the focus before the next key is delivered: over SSH a typist's tab
#: and the characters after it arrive together, and the characters belong in the new field
#: (the help's Dialogs section explains them); a key typed just before them has gone its way
#: first (OrderedKeys: a space ticks the box it was typed at)
FOCUS_BINDINGS = (
    Binding("tab", "focus_next", show=False, priority=True),
    Binding("shift+tab", "focus_previous", show=False, priority=True),
)


class AppSetupError(ValueError):
    """The app cannot start with these settings; the message says what to change."""


class WorkbenchApp(ScreenHost[None], OrderedKeys):
    """VIPLE Maze Lab Workbench."""

    # (ScreenHost first: Textual gathers an app's default CSS along its first bases)

    CSS_PATH = "app.tcss"
    TITLE = "VIPLE Maze Lab Workbench"
    COMMANDS = ScreenHost.COMMANDS | {WorkbenchCommands}
    BINDINGS: ClassVar[list[BindingType]] = [
        *bindings(*APP_KEY_IDS),
        *FOCUS_BINDINGS,
    ]

    #: frames drawn so far (a plain attribute: a reactive one costs a lookup on every tick)
    frames: int = 0
    #: the app is its process's one app for the process's life (``workbench`` on a terminal
    #: sets it; tests run many apps in one process and leave it off)
    holds_process: bool = False

    def __init__(
        self,
        station: LabStation,
        settings: AppSettings,
        *,
        names_given: bool = False,
        seat: Seat | None = None,
    ) -> None:
        """The app on ``station`` with ``settings`` as :func:`make_app` completes them (the
        maze file and the pair named); ``names_given``: whoever started the app named the pair
        (it is kept as the last pair at this workbench). With a ``seat`` the app is a spare:
        it shows the names dialog and waits there for its session (:meth:`take_seat`)."""
        super().__init__()
        #: a spare's wait for its session (None once it has one, or was never a spare)
        self.seat = seat
        self._labs: LabsScreen | None = None
        self.endpoints: Endpoints | None = None
        #: sends the files saved in a served student's workspace to the course database
        self.pusher: WorkspacePusher | None = None
        #: the endpoints' status line as last handed to the screens
        self._connection = ""
        self._sit(station, settings, names_given)
        self.set_reactive(WorkbenchApp.unicode, settings.unicode)
        self.mark_ascii(update=False)
        # the stylesheets as the fork server parsed them (a served app), else parsed here
        warmup.seed(self.stylesheet)
        self._last_tick = perf_counter()
        #: the clock ticks at REST_HZ (True) or at the settings' tick rate (False)
        self._resting = False
        self._rest_period = max(1.0 / REST_HZ, 1.0 / settings.tick_hz)
        self._clock: LoopClock | None = None
        self._drawn: tuple[object, ...] = ()
        self._too_small: TooSmallScreen | None = None
        #: the size the app started with was announced again (see _on_resize)
        self._sized = False
        self._main: MainScreen | None = None
        #: the names dialog was shown, and answered; what the message line last said
        self._names_asked = False
        self._named = False
        #: a key or a click has come from the terminal
        self._input_seen = False
        self._last_said = ""
        #: the screens a screen may ask for (OpenScreen), each with the way it opens
        #: the file the FSM editor is asked to open ("" its own choice)
        self._fsm_path = ""
        self._screens: dict[ScreenName, Callable[[], None]] = {
            "main": self._open_main,
            "editor": self._open_editor,
            "runs": self._open_runs,
            "labs": self._open_labs,
            "fsm": self._open_fsm_editor,
        }

    def _sit(self, station: LabStation, settings: AppSettings, names_given: bool) -> None:
        """What is the session's own: the settings, the pair, the course store, the station."""
        self.settings = settings
        self._names_given = names_given
        self.student = settings.student or _login_name()
        self.partner = settings.partner
        #: the course store's life (opening, retries, the last try): the app only says it
        self.course = CourseStore(settings.data_dir, settings.db, self.student)
        self.course.subscribe(self._store_news)
        self._viple_configs = viple_configs(settings)
        self.station = station
        self.maze_path = settings.maze_path
        #: the maze the message line last named
        self._maze_named = station.maze

    async def take_seat(self, settings: AppSettings) -> None:
        """A spare app becomes its session's: the session's settings (those every session
        shares are the spare's already), a station of its own, the names dialog showing the
        student's name, and the session's start (:meth:`_start_session`). Settings the app
        cannot start with end it with status 2 and the reason in its error output."""
        self.seat = None
        try:
            station, named, given = open_station(settings)
        except AppSetupError as exc:
            print(f"workbench: {exc}", file=sys.stderr)
            self.exit(return_code=2)
            return
        self._sit(station, named, given)
        from .dialogs.identity import IdentityDialog

        for screen in self.screen_stack:
            if isinstance(screen, IdentityDialog):
                screen.show_student(self.student)
        await self._start_session()

    def who(self) -> str:
        """Who is at the robot, for the message line ("" when nobody was named)."""
        if not self.settings.ask_names:
            return ""
        names = self.student + (f" & {self.partner}" if self.partner else "")
        return f"{names} ({self.settings.role})"

    def get_default_screen(self) -> Screen:
        if self.settings.ask_names:
            return ArrivalScreen()  # the main screen follows the names (see _open_main)
        return self._new_main()

    def _new_main(self) -> MainScreen:
        self._main = MainScreen(
            self.station, unicode=self.unicode, who=self.who(), maze_path=self.maze_path
        )
        return self._main

    def _open_main(self) -> None:
        """Put the main screen in the arrival screen's place once the names are given and the
        arrival screen is on top (not while the terminal is too small, say)."""
        if self._main is not None or not self._named or not isinstance(self.screen, ArrivalScreen):
            return
        main = self._new_main()
        main.show_message(self._last_said)
        main.show_connection(self._connection)
        self.add_mode("main", lambda: main)  # its own stack: the arrival screen stays below
        self.switch_mode("main")

    def say(self, text: str) -> None:
        self._last_said = text  # for the main screen when it comes after the names
        super().say(text)

    # Textual runs each class's on_mount in turn (the host's too): a handler, not an override
    async def on_mount(self) -> None:  # type: ignore[override]
        if self.seat is not None:
            self.seat.wait(self)  # a spare: its session starts when it comes
        else:
            await self._start_session()
        self._check_size(self.size.width, self.size.height)
        self._ask_for_names()

    async def _start_session(self) -> None:
        """The session's start: its VIPLE endpoints, the clock, the course store's work."""
        tcp, ws = self._viple_configs
        if not self.settings.ws_at_start:
            ws = None  # later: a WebSocket exercise's set-up or the v key starts it
        if tcp is not None or ws is not None:
            self.endpoints = await Endpoints.open(self.station, tcp, ws)
        self.mark_ascii()
        self._show_maze_title()
        self._last_tick = perf_counter()
        self._clock = LoopClock(
            self._tick, 1.0 / self.settings.tick_hz, partial(end_with_error, self)
        )
        self.station.on_activity = self.wake
        if self.settings.connect_hint:
            self.say(self.hint_line())
        if self.holds_process or serves(self):
            # the process holds this one app for its whole life (a served session's, for the
            # whole class): what start-up built lives as long as it, so the garbage collector's
            # full passes (some 70 ms each, a stutter of the robot every half minute while it
            # drives) leave it alone from the first screen on
            self.call_after_refresh(gc.freeze)
        self._start_pusher()
        # what an earlier app could not save: written as soon as the database answers
        self.course.save_kept()
        if self._names_given and not self.settings.ask_names:
            self._remember_pair()

    def on_unmount(self) -> None:
        """However the app ends (quitting, or its session closing), its workspace sends stop:
        a file not sent yet is on this server's disk, and the next session's start sends it."""
        if self.pusher is not None:
            self.pusher.stop()

    def _ask_for_names(self) -> None:
        """The names dialog, once, when the terminal is big enough for it (else the size
        message comes first and the dialog after it)."""
        if not self.settings.ask_names or self._names_asked or self._too_small is not None:
            return
        from .dialogs.identity import IdentityDialog

        self._names_asked = True
        dialog = IdentityDialog(
            self.student, self.partner, student_fixed=self.settings.student_fixed
        )
        self.push_screen(dialog, self._on_names)

    def _remember_pair(self) -> None:
        """Keep the pair for the next start at this workbench (never for a served student:
        the data folder there is the server's)."""
        if self.station.files.confined:
            return
        with contextlib.suppress(OSError):
            save_last_pair(resolve_data_dir(self.settings.data_dir), self.student, self.partner)

    def hint_line(self) -> str:
        """The connect hint for the message line: all of it when it fits beside the names,
        else where to find it (the help shows it whole, wrapped)."""
        hint = self.settings.connect_hint
        if len(hint) <= self.size.width - 4 - len(self.who()):
            return hint
        return "VIPLE from your computer: press ? for the ssh command"

    def _on_names(self, names: tuple[str, str] | None) -> None:
        """The names dialog's answer (None: the names it opened with); the main screen, built
        now, shows them."""
        self._named = True
        if names is not None:
            self._set_names(*names)  # before the labs open: the dialog is modal

    def _set_names(self, student: str, partner: str) -> None:
        """Who is at the robot, kept for the next start and shown on every message line."""
        self.student, self.partner = student, partner
        self._remember_pair()
        who = self.who()
        for screen in self.screen_stack:
            if isinstance(screen, ShowsStatus):
                screen.show_who(who)

    # -- time --------------------------------------------------------------------------------
    def _tick(self) -> None:
        if not self.is_running:  # the app is closing its screens: the clock stops
            if self._clock is not None:
                self._clock.stop()
            return
        station = self.station
        if self.endpoints is not None:
            self._show_connection(self.endpoints.summary())
        steps = self._advance()
        if steps or self._state() != self._drawn:
            self.refresh_views()
        self._rest(station.at_rest)

    def _state(self) -> tuple[object, ...]:
        """What, beside the steps, asks for a redraw when it changes: a paused station still
        shows a live VIPLE program's counters and the commands it holds."""
        station = self.station
        return (
            station.paused,
            station.notice,
            station.driving,
            len(station.runs),
            station.held_count,
            self._connection,
        )

    def _advance(self) -> int:
        """Hand the station the real time since the last tick; none passes behind the names
        asked at start, nor behind a dialog while nothing but the clock would change (a run's
        time is the time the robot could have moved)."""
        now = perf_counter()
        elapsed = now - self._last_tick
        self._last_tick = now
        station = self.station
        if self._behind_dialog() and (station.paused or station.idle):
            return 0
        # at rest the ticks are far apart on purpose: all the time they owe is kept
        lag = self._rest_period + station.pacer.max_lag if self._resting else None
        return station.advance(elapsed, lag)

    def _behind_dialog(self) -> bool:
        """A dialog, or the arrival screen asking the names, is in front of the station."""
        stack = self.screen_stack
        top = stack[-1] if stack else None
        return isinstance(top, (ModalScreen, ArrivalScreen))

    def _rest(self, resting: bool) -> None:
        """Tick at REST_HZ while the station is at rest, else at the full rate."""
        if resting == self._resting or self._clock is None:
            return
        self._resting = resting
        if resting:
            self._clock.set_period(self._rest_period)
        else:  # what woke it is drawn at once, then the clock ticks at its rate
            self._clock.set_period(1.0 / self.settings.tick_hz, at_once=True)

    def wake(self) -> None:
        """Something is about to change the station (a key, a click, a VIPLE command): the time
        owed at rest is run first, as it would have been, and the clock ticks at full rate."""
        if self._resting:
            self._advance()
            self._rest(False)

    async def on_event(self, event: events.Event) -> None:
        if isinstance(event, (events.Key, events.MouseDown)):
            self._input_comes()
            await super().on_event(event)
            self._input_taken()
            return
        await super().on_event(event)

    def _input_comes(self) -> None:
        self._input_seen = True
        self.wake()

    def _input_taken(self) -> None:
        if self._clock is not None:
            self._clock.nudge()  # awake anyway: the tick (with the key in it) comes now

    def take_typed_key(self, key: str) -> bool:
        """Run a typed key's action at once when the screen has it as a quick action
        (``workbench/tui/serving/quick_keys.py``); False: the key goes the usual way, as a key
        event."""
        stack = self.screen_stack  # (empty while the app starts or ends)
        screen = stack[-1] if stack else None
        if not isinstance(screen, QuickKeys) or self.keys_on_their_way:
            return False
        self._input_comes()  # the time owed at rest first, as for a key event
        action = screen.quick_action(key)
        if action is None:
            return False
        as_key_press(self, screen)
        try:
            action()
        except Exception as error:  # as an action's error in a key event: shown, the app ends
            end_with_error(self, error)
            return True
        self._input_taken()
        return True

    def on_app_blur(self, event: events.AppBlur) -> None:
        """A served app's driver reports the terminal unfocused as it starts (it was made for
        a web page): over SSH the student is typing into that terminal, so a blur before any
        input is not taken (it restyled the whole first screen, and the first key again)."""
        if not self._input_seen:
            event.prevent_default()

    def refresh_views(self) -> None:
        """Draw the station's current snapshot on every screen of the stack that shows one;
        at rest (nothing moves, and no time passes behind a dialog) with a dialog open, on the
        dialog only: the screen dimmed under it is brought up to date when it is on top again
        (the clock had redrawn a whole dimmed screen every second, 8 KB a second over SSH)."""
        station = self.station
        self._drawn = self._state()
        snapshot = station.snapshot()
        stack = self.screen_stack
        dialog = stack[-1] if stack and isinstance(stack[-1], ModalScreen) else None
        top = dialog if station.at_rest else None
        for screen in stack:
            if isinstance(screen, ShowsSnapshot) and top in (None, screen):
                screen.show_snapshot(snapshot)
        labs = self._labs
        if labs is not None and labs not in self.screen_stack:
            labs.track()  # the exercise's progress is saved while the student drives
        self.frames += 1

    # -- size --------------------------------------------------------------------------------
    def on_resize(self, event: events.Resize) -> None:
        known = handled_size(self)  # None until Textual has handled the app's first resize
        if known is not None and not self._sized:
            self._sized = True
            if event.size == known:
                # Textual's web driver announces, once the app runs, the size the app
                # started with, and Textual then lays out and draws every screen again: a
                # quarter of a served app's work to its first screen. That one is let go (a
                # later resize to the same size still redraws all, as after a reattach).
                event.prevent_default()
                return
        self._check_size(event.size.width, event.size.height)

    def _check_size(self, width: int, height: int) -> None:
        small = width < MIN_SIZE[0] or height < MIN_SIZE[1]
        if small and self._too_small is None:
            self._too_small = TooSmallScreen(MIN_SIZE)
            self.push_screen(self._too_small)
        elif small and self._too_small is not None:
            self._too_small.show_size(width, height)
        elif not small and self._too_small is not None:
            screen, self._too_small = self._too_small, None
            if self.screen is screen:
                self.pop_screen()
            self._ask_for_names()

    def check_action(self, action: str, parameters: tuple[object, ...]) -> bool | None:
        """While the terminal is too small, or while the screen takes every key (all keys to a
        running program), only quitting works."""
        screen = self.screen_stack[-1] if self.screen_stack else None
        if isinstance(screen, TakesAllKeys) and screen.takes_all_keys:
            return action == "quit"
        return self._too_small is None or action == "quit"

    # -- what screens ask for -------------------------------------------------------------------
    def on_station_changed(self, message: StationChanged) -> None:
        self.wake()
        self.refresh_views()

    def on_maze_changed(self, message: MazeChanged) -> None:
        self.maze_changed(message.path)

    def on_set_up_done(self, message: SetUpDone) -> None:
        self.set_up_done(message.setup)

    def on_open_screen(self, message: OpenScreen) -> None:
        self._fsm_path = message.path
        self._screens[message.screen]()

    def on_start_endpoint(self, message: StartEndpoint) -> None:
        self.run_worker(self.open_endpoint(message.role), group="endpoints")

    # -- screens -------------------------------------------------------------------------------
    def action_help(self) -> None:
        if not isinstance(self.screen, HelpScreen):
            self.push_screen(HelpScreen(self.station.profile, self.settings.connect_hint))

    def _open_editor(self) -> None:
        # the bundled mazes (and the labs' set-up mazes) are never overwritten, nor is a file
        # outside a served student's workspace: saving one asks where to keep the copy
        path = self.maze_path
        writable = path is not None and self.station.files.allows_writing(path)
        saves_to = str(path) if writable else None
        self.push_screen(EditorScreen(self.station, saves_to, unicode=self.unicode), self._edited)

    def _open_fsm_editor(self) -> None:
        """The FSM editor on the file asked for, else the chosen algorithm's file (a built-in
        opens as the text of a copy to save), else a new machine."""
        path = self._fsm_path
        algorithm = self.station.algorithm
        if not path and algorithm is not None and algorithm.source:
            path = algorithm.source
        self.push_screen(FsmEditorScreen(self.station, path, unicode=self.unicode))

    def _edited(self, maze: Maze | None) -> None:
        self.maze_changed()

    def maze_changed(self, path: str | os.PathLike | None = None) -> None:
        """The station has a new maze (or profile): follow it, and its file when one is given
        (the editor saves there unless it is a bundled maze)."""
        if path is not None:
            self.maze_path = Path(path)
            if self._main is not None:
                self._main.follow_maze_file(self.maze_path)
        maze = self.station.maze
        if maze is not self._maze_named:
            self._maze_named = maze
            said = self._main.message if self._main is not None else ""
            if maze.name not in said:  # else the screen has said it already
                self.say(maze_message(self.station))
        self._show_maze_title()
        self.refresh_views()

    def _show_maze_title(self) -> None:
        self.sub_title = f"{self.station.maze.name} ({self.station.profile})"

    def _open_runs(self) -> None:
        self.push_screen(RunsScreen(self.station, unicode=self.unicode))

    def _open_labs(self) -> None:
        if self._labs is None:
            self._labs = LabsScreen(
                self.station,
                self.student,
                self.partner,
                # a served student's terminal is theirs: an instructor never types a
                # passphrase there (they sign at their own console)
                signs_here=not self.station.files.confined,
                course=self.course,
            )
            self.install_screen(self._labs, name="labs")
            # the screen comes up at once; the store is opened and read beside it (a served
            # student's login name is the only one that is theirs: it is not respelled)
            self.course.open_for(
                self.student, self.partner, respell=not self.station.files.confined
            )
        self.push_screen("labs")

    @property
    def store(self) -> Store | None:
        """The course store, once open (None before, or when it could not be opened)."""
        return self.course.store

    def _store_news(self, event: StoreEvent) -> None:
        """What the course store did (called from its threads): handled on the event loop."""
        self.post_message(StoreNews(event))

    def on_store_news(self, message: StoreNews) -> None:
        """The pair as the store spells them, and the changes kept by an earlier app; the
        labs screen hears the rest (and the names too)."""
        event = message.event
        if self._labs is not None:
            self._labs.post_message(StoreNews(event))
        if isinstance(event, Opened) and (event.student, event.partner) != (
            self.student,
            self.partner,
        ):
            self._set_names(event.student, event.partner)
        elif isinstance(event, KeptSaved):
            self._say("saving resumed: the changes kept while the course database was away "
                      "are saved")  # fmt: skip
        elif isinstance(event, KeptNotSaved):
            self._say(f"changes kept from before were not saved: {event.error}")

    def _start_pusher(self) -> None:
        """With a course database, a served student's workspace follows them to any server:
        each file saved here is sent to the database as it is saved, in a thread of its own."""
        workspace = self.station.files.workspace
        if self.settings.workspace is None or workspace is None:
            return

        def tell(text: str) -> None:
            self.call_from_thread(self._say, text)

        self.pusher = self.course.workspace_pusher(workspace, tell)

    def set_up_done(self, setup: Setup | None = None) -> None:
        """A lab's set-up changed the station: follow its maze and profile, and start the VIPLE
        endpoint an exercise done from VIPLE needs."""
        self.maze_changed(setup.maze.path if setup is not None else None)
        if setup is not None and setup.controller.kind == "viple":
            self.run_worker(self.open_endpoint(setup.controller.value), group="endpoints")

    async def open_endpoint(self, role: str) -> str:
        """Start the VIPLE endpoint of ``role`` (tcp or ws) if it is not running; says how to
        connect (also returned)."""
        tcp, ws = self._viple_configs
        if self.endpoints is None:
            self.endpoints = Endpoints()
        endpoints, station = self.endpoints, self.station
        if role == "tcp":
            if await endpoints.start_tcp(station, tcp or TcpConfig()) and endpoints.tcp:
                text = f"VIPLE: connect your program (TCP) to localhost:{endpoints.tcp.port}"
            else:
                text = endpoints.problems[-1]
        else:
            await endpoints.start_ws(station, ws or WsConfig())
            url = endpoints.ws.config.url if endpoints.ws else ""
            text = f"VIPLE: start your program's WebSocket server; the robot connects to {url}"
        if self.settings.connect_hint:
            text = self.hint_line()
        self._show_connection(endpoints.summary())
        self._say(text)
        return text

    def _say(self, message: str) -> None:
        self.say(message)
        self.refresh_views()

    def _show_connection(self, text: str) -> None:
        """Hand the VIPLE endpoints' status line to the screens that show it, when it changed."""
        endpoints = self.endpoints
        tcp = endpoints.tcp if endpoints is not None else None
        self.station.tcp_port = tcp.port if tcp is not None else None  # (as the panel says)
        if text == self._connection:
            return
        self._connection = text
        for screen in self.screen_stack:
            if isinstance(screen, ShowsStatus):
                screen.show_connection(text)

    async def action_quit(self) -> None:
        """Quit; an editor with unsaved changes asks first (save / discard / cancel)."""
        editors = [
            s
            for s in self.screen_stack
            if isinstance(s, EditorScreen | FsmEditorScreen) and s.dirty
        ]
        if editors:
            editors[-1].ask_before(lambda: self.run_worker(self._shut_down()))
        else:
            await self._shut_down()

    async def _shut_down(self) -> None:
        self.station.close()
        sent: asyncio.Future[bool] | None = None
        if self.pusher is not None:
            # the run record closed just now goes while the database answers (alongside the
            # last try below); what does not go is on this server's disk, and is sent when
            # the student's next session starts
            sent = asyncio.ensure_future(
                asyncio.to_thread(self.pusher.wait_idle, STORE_LAST_TRY_SECONDS)
            )
        # a last try for what the database did not get yet (never shown as saved); while it
        # is away the pending writes are in their file already, for the next app
        await asyncio.to_thread(self.course.finish, STORE_LAST_TRY_SECONDS)
        if sent is not None and self.pusher is not None:
            await sent
            self.pusher.stop()
        if self.endpoints is not None:
            await self.endpoints.close()
        self.exit()


def make_app(settings: AppSettings, seat: Seat | None = None) -> WorkbenchApp:
    """The workbench app with ``settings`` (the maze default: the bundled Unity maze); with a
    ``seat``, a spare app waiting for its session (:meth:`WorkbenchApp.take_seat`).

    Neither VIPLE endpoint runs unless the settings ask for it (a lab exercise's set-up starts
    the one it needs). The student (default: the pair last at this workbench, else the login
    name) and partner do the labs; with a workspace folder (a served student) the app opens
    files only there and in the bundled mazes, labs and starters, and writes only there.

    Raises :class:`AppSetupError` with a message for the user when the maze cannot be read or
    a setting is not one the workbench knows.
    """
    station, named, names_given = open_station(settings)
    return WorkbenchApp(station, named, names_given=names_given, seat=seat)


def open_station(settings: AppSettings) -> tuple[LabStation, AppSettings, bool]:
    """The station ``settings`` ask for, the settings completed (the maze file and the pair
    named), and whether whoever started the app named the pair; AppSetupError as for
    :func:`make_app`."""
    path = settings.maze_path or default_maze_path()
    profile, noise, role = settings.profile, settings.noise, settings.role
    if profile is not None and profile not in PROFILES:
        raise AppSetupError(f"unknown profile {profile!r}: use one of {', '.join(PROFILES)}")
    if noise is not None and noise not in NOISE_LEVELS:
        raise AppSetupError(f"unknown noise level {noise!r}: use one of {', '.join(NOISE_LEVELS)}")
    if role not in ROLES:
        raise AppSetupError(f"unknown role {role!r}: use one of {', '.join(ROLES)}")
    student, partner = settings.student, settings.partner
    if not student and settings.workspace is None and not settings.student_fixed:
        # the pair at this workbench last time, offered instead of the login name
        last = read_last_pair(resolve_data_dir(settings.data_dir))
        if last is not None:
            student, partner = last[0], partner or last[1]
    try:
        student, partner = check_pair(student or _login_name(), partner)
    except NameProblem as exc:
        raise AppSetupError(str(exc)) from None
    tick_hz = settings.tick_hz
    if not (math.isfinite(tick_hz) and tick_hz > 0):
        raise AppSetupError(f"the tick rate must be a number of Hz above 0, not {tick_hz}")
    try:
        viple_configs(settings)
    except ValueError as exc:
        raise AppSetupError(str(exc)) from None
    if settings.report_ms is not None:
        try:
            check_report_ms(settings.report_ms)
        except ValueError as exc:
            raise AppSetupError(f"a VIPLE program's {exc}") from None
    try:
        maze = load_maze(path)
    except MazeError as exc:
        problems = "\n".join(f"  {p}" for p in exc.problems)
        raise AppSetupError(f"cannot open the maze {str(path)!r}:\n{problems}") from None
    workspace = settings.workspace
    try:
        files = (
            FileAccess.confined_to(workspace, settings.uploads) if workspace is not None else LOCAL
        )
    except OSError as exc:
        raise AppSetupError(f"cannot use the workspace folder {workspace}: {exc}") from None
    record_dir = str(settings.record_dir) if settings.record_dir is not None else None
    try:
        station = LabStation.open(
            maze,
            profile,
            seed=settings.seed,
            noise=noise,
            record_dir=record_dir,
            record_quota=settings.record_quota,
            files=files,
        )
    except ValueError as exc:
        raise AppSetupError(f"cannot set up the robot: {exc}") from None
    station.pause(settings.paused)
    station.report_ms = settings.report_ms
    # max speed may use at most 60 % of each frame, so keys and drawing stay responsive
    station.pacer.budget = 0.6 / tick_hz
    named = replace(settings, maze_path=path, student=student, partner=partner)
    return station, named, bool(settings.student)


def viple_configs(settings: AppSettings) -> tuple[TcpConfig | None, WsConfig | None]:
    """The VIPLE endpoints the settings ask for at start (TCP, WebSocket; None: not that
    one); ValueError names a port or URL that cannot be used."""
    tcp = TcpConfig(port=settings.tcp_port) if settings.tcp_port else None
    ws = WsConfig(url=settings.ws_url) if settings.ws_url else None
    return tcp, ws


def maze_message(station: LabStation) -> str:
    """What the message line says when a maze goes on the station: its name, and the profile
    the robot keeps when the file was made for another."""
    maze = station.maze
    text = f"the robot is on {maze.name}"
    if maze.profile and maze.profile != station.profile:
        text += (
            f", still with the {station.profile} profile (the maze file names {maze.profile}; "
            f"--profile {maze.profile} at start uses it)"
        )
    return text


def _login_name() -> str:
    try:
        return getpass.getuser()
    except (KeyError, OSError):
        return "student"


def warm_up() -> None:
    """Run once in the lab server's fork server, before it forks the sessions' apps: the app a
    served student gets, run to its first screen (:func:`workbench.tui.serving.warmup.prepare`)."""
    warmup.prepare(
        lambda folder: make_app(
            AppSettings(
                student="warmup",
                ask_names=True,
                student_fixed=True,
                data_dir=Path(folder),
                workspace=Path(folder),
                connect_hint="VIPLE: warming up",
            )
        )
    )
