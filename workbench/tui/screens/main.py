"""The main screen: the maze with the robot, and around it everything a lab needs at a glance.

Layout: the maze view (most of the space) over the run status, a side panel with the key
legend, the sensor readings by port and the algorithm's live state, the message line and the
footer. Every action here calls the station; the screen only draws what the station reports.
"""

from __future__ import annotations

import os
from collections.abc import Callable
from pathlib import Path
from time import monotonic
from typing import ClassVar

from textual import events
from textual.app import ComposeResult
from textual.binding import BindingType
from textual.containers import Horizontal, Vertical

from workbench.control.station import ALGORITHM_FAILED, PROGRAM_STOPPED, LabStation, Notice
from workbench.files.workspace import OutsideWorkspace
from workbench.fsm.machine import FsmError
from workbench.program.choice import ProgramChoice
from workbench.program.keys import known_key
from workbench.sim.driver import Driver
from workbench.sim.maze import MazeError
from workbench.sim.mazeio import load_maze
from workbench.sim.sensors import SensorConfigError
from workbench.sim.session import Snapshot

from ..host import (
    FollowsUnicode,
    MazeChanged,
    OpenScreen,
    ShowsSnapshot,
    ShowsStatus,
    StartEndpoint,
    StationChanged,
    TakesAllKeys,
    ToggleUnicode,
)
from ..keys import MAIN_KEY_IDS, PROGRAM_KEYS, bindings
from ..record_words import record_words
from ..serving.compositor import use_live_compositor
from ..serving.prompt_frames import PromptFrames
from ..serving.quick_keys import QuickKeys
from ..serving.single_layout import SingleLayout
from ..widgets.algorithm_state import AlgorithmState
from ..widgets.key_bar import KeyBar
from ..widgets.key_legend import KeyLegend
from ..widgets.maze_view import MazeView
from ..widgets.message_bar import MessageBar
from ..widgets.program_state import ProgramState
from ..widgets.run_status import RunStatus
from ..widgets.sensor_readings import SensorReadings

#: how often the text panels follow a running robot (the maze view follows every tick): twice a
#: second is as often as a person reads a changing figure, and each update is a frame of its own
#: (at 4 Hz the panels made most of a driving session's frames); paused, stepped or ended, the
#: panels show the exact figures at once
PANEL_HZ = 2.0
#: the share of a panel period after which the panels also follow in a frame the maze view
#: draws anyway: one frame instead of two, at about the same rate
PANEL_WITH_MAZE = 0.6


class MainScreen(
    ShowsSnapshot,
    ShowsStatus,
    FollowsUnicode,
    TakesAllKeys,
    QuickKeys,
    PromptFrames,
    SingleLayout,
):
    """Drive, watch and set up the robot."""

    # the side panel moves beside the maze on a wide terminal (app.tcss); only this screen
    # has the classes, so the dialogs are not restyled for them when they open
    # (Screen declares it "ClassVar[...] | None", which mypy reads as an instance variable)
    HORIZONTAL_BREAKPOINTS: ClassVar[list[tuple[int, str]]] = [(0, "-narrow"), (110, "-wide")]  # type: ignore[misc]

    #: the driving keys' actions, run straight from the key on a served session (QuickKeys)
    QUICK_ACTIONS: ClassVar[frozenset[str]] = frozenset({"drive", "pause", "step", "speed"})

    # the keys pressed again and again while driving are priority bindings: the screen takes
    # them before the focused widget (the transition log, which has no use for them) would, so
    # a key press runs its action at once instead of bubbling up through the side panel
    BINDINGS: ClassVar[list[BindingType]] = [*bindings(*MAIN_KEY_IDS)]

    #: the last snapshot drawn (a plain attribute: set on every tick, it never repaints)
    snapshot: Snapshot | None = None

    def __init__(
        self,
        station: LabStation,
        unicode: bool = False,
        trail: bool = True,
        who: str = "",
        maze_path: Path | None = None,
    ) -> None:
        super().__init__()
        #: who is at the robot, for the message line
        self.who = who
        #: the file of the maze on the station (where the maze dialog starts)
        self.maze_path = maze_path
        # the maze and the panels change a few cells at a time, many times a second
        use_live_compositor(self)
        self.station = station
        self._ready = False
        self._unicode = unicode
        self._trail = trail
        self._driving: object = None
        self._moment: tuple[object, ...] = ()
        self._panels_at = 0.0
        #: the message line's text, and the VIPLE endpoints' status line
        self._said = ""
        #: while what the message says of the station stays true (None: it says what was
        #: done, which later work does not make untrue); the line clears once it is not
        self._said_while: StillTrue | None = None
        self._connection = ""
        self._notice: Notice | None = station.notice
        #: a live VIPLE program's commands are being held (paused), and the line said so
        self._holding = False
        #: every key goes to the running program (ctrl+k), not only the free ones
        self._all_keys = False

    def compose(self) -> ComposeResult:
        station = self.station
        self._maze_view = MazeView(
            station.maze, unicode=self._unicode, trail=self._trail, id="maze"
        )
        self._run_status = RunStatus(id="run")
        self._legend = KeyLegend(station.profile, id="legend")
        self._readings = SensorReadings(id="readings")
        self._algorithm = AlgorithmState(id="algorithm")
        self._program = ProgramState(id="program")
        self._message = MessageBar(self.who, id="message")
        with Horizontal(id="body"):
            with Vertical(id="stage"):
                yield self._maze_view
                yield self._run_status
            with Vertical(id="side"):
                yield self._legend
                yield self._readings
                yield self._algorithm
                yield self._program
        yield self._message
        yield KeyBar()

    def on_mount(self) -> None:
        self._ready = True
        self.show_snapshot(self.station.snapshot())

    def on_screen_resume(self) -> None:
        view = self._maze_view
        if view.maze is not self.station.maze:
            view.set_maze(self.station.maze)
            view.clear_trail()
        self._legend.profile = self.station.profile
        self.show_snapshot(self.station.snapshot())

    # -- drawing ---------------------------------------------------------------------------
    @property
    def unicode(self) -> bool:
        return self._maze_view.unicode

    def show_snapshot(self, snapshot: Snapshot) -> None:
        """Draw one snapshot: each widget repaints only what changed."""
        if not self._ready:
            return  # the app ticks while the screen is still being built
        station = self.station
        self.snapshot = snapshot
        unicode = self.unicode
        if self._all_keys and not station.program_drives:
            self._all_keys = False  # the program stopped: the keys are the workbench's
            self.refresh_bindings()
        if station.driving is not self._driving:
            self._driving = station.driving
            if station.driving is not None:
                self._maze_view.clear_trail()  # a new run starts from the start block
        drawn = self._maze_view.show(snapshot, station.session.world.cell)
        # the text panels follow at PANEL_HZ while the robot runs (every byte counts over SSH),
        # early in a frame the maze view draws anyway; at once when paused (steps, snapshots)
        # and when who drives or the state changes
        now = monotonic()
        if station.notice is not self._notice:
            self._notice = station.notice
            if station.notice is not None:
                self._said = worded(station.notice, station.files.shown)
                self._said_while = None
        holding = station.held_count > 0
        if holding != self._holding:  # (a program that connected while paused, too)
            self._holding = holding
            if holding:
                self._said, self._said_while = HELD_WHILE_PAUSED, is_paused
        if self._said_while is not None and not self._said_while(station):
            self._said, self._said_while = "", None  # the message is no longer true
        moment = (
            station.paused,
            self._said,
            snapshot.driver,
            snapshot.state,
            self._connection,
            station.program,
            self._all_keys,
        )
        since = (now - self._panels_at) * PANEL_HZ  # in panel periods
        if (
            station.paused
            or moment != self._moment
            or since >= 1
            or (drawn and since >= PANEL_WITH_MAZE)
        ):
            self._moment = moment
            self._panels_at = now
            self._readings.show(snapshot, station.profile)
            self._run_status.show(snapshot, station, unicode, self._connection)
            program = station.program is not None
            self._algorithm.display = not program
            self._program.display = program
            if program:
                self._program.show(station, self._all_keys)
            else:
                self._algorithm.show(station, unicode)
            self._message.message = self._said

    def refresh_views(self) -> None:
        """Redraw after an action: the app draws every screen that shows the station, this one
        and the dialogs over it."""
        self.post_message(StationChanged())

    @property
    def message(self) -> str:
        """What the message line says now."""
        return self._said

    def show_message(self, text: str, true_while: StillTrue | None = None) -> None:
        self._said = text
        self._said_while = true_while if text else None
        if self._ready:
            self._message.message = text

    def show_connection(self, text: str) -> None:
        self._connection = text

    def show_who(self, who: str) -> None:
        """Who is at the robot, on the right of the message line."""
        self.who = who
        for bar in self.query(MessageBar):  # (none until the screen is composed)
            bar.who = who

    def follow_maze_file(self, path: Path) -> None:
        """The file of the maze now on the station: the maze dialog starts in its folder."""
        self.maze_path = path

    def say(self, message: str, true_while: StillTrue | None = None) -> None:
        """Say ``message`` on the message line; with ``true_while``, only for as long as
        that holds of the station (it is checked at each redraw)."""
        self.show_message(message, true_while)
        self.refresh_views()

    # -- actions -------------------------------------------------------------------------------
    def action_drive(self, key: str) -> None:
        station = self.station
        program = station.program_drives
        self._said, self._said_while = "", None
        station.key(key)
        if program and not station.program_drives:
            self._said = "program stopped: the keys drive"
        if station.paused or program:
            self.refresh_views()
        # else the next tick draws it, within 1/20 s, with the robot already moving: drawing
        # now as well would draw every key twice while a student drives

    @property
    def takes_all_keys(self) -> bool:
        """Every key but ctrl+k and ctrl+q goes to the running program."""
        return self._all_keys and self.station.program_drives

    def check_action(self, action: str, parameters: tuple[object, ...]) -> bool | None:
        running = self.station.program_drives
        if action == "program_key":
            return running
        if action == "all_keys_to_program":
            return running and not self._all_keys
        if action == "keys_back":
            return self.takes_all_keys
        return not self.takes_all_keys

    def action_program_key(self, key: str) -> None:
        """An arrow while a program drives."""
        self.station.key(key)
        self.refresh_views()

    def action_all_keys_to_program(self) -> None:
        self._all_keys = True
        self.refresh_bindings()
        self.say("every key goes to the program: ctrl+k gives the keys back, ctrl+q quits")

    def action_keys_back(self) -> None:
        self._all_keys = False
        self.refresh_bindings()
        self.say("the keys are the workbench's again (space stops the program)")

    def on_key(self, event: events.Key) -> None:
        """Arrows, digits and the free letters reach a running program; every key does
        while all keys go to it (keys VIPLE has no number for do nothing then)."""
        key = event.key
        if not self.station.program_drives:
            return
        if self.takes_all_keys:
            event.stop()
            event.prevent_default()
            name = known_key(key)
            if name is not None:
                self.station.type_to_program(name)
                self.refresh_views()
            return
        if key in PROGRAM_KEYS:
            event.stop()
            event.prevent_default()
            self.station.key(key)
            self.refresh_views()

    def action_pause(self) -> None:
        station = self.station
        paused = station.toggle_pause()
        if paused and station.live_viple is not None:
            self.say(HELD_WHILE_PAUSED, is_paused)
        else:
            self.say("paused: n steps, p resumes" if paused else "", is_paused)

    def action_step(self) -> None:
        station = self.station
        station.pause()
        station.step(station.session.every)
        self.refresh_views()

    def action_speed(self) -> None:
        station = self.station
        if station.next_speed() or station.live_viple is None:
            self.refresh_views()
        else:
            self.say(speed_held(station.live_viple), live_viple_drives)

    def action_reset(self) -> None:
        self.station.reset_robot()
        self._maze_view.clear_trail()
        self.say("")

    def action_sensors(self) -> None:
        from ..dialogs.sensor_ports import SensorPortsModal

        self.app.push_screen(SensorPortsModal(self.station))

    def action_algorithm(self) -> None:
        from ..dialogs.algorithm import AlgorithmModal

        self.app.push_screen(AlgorithmModal(self.station))

    def action_run_algorithm(self) -> None:
        station = self.station
        if station.driving is not None:
            what = "program" if station.program_drives else "algorithm"
            station.stop("stopped")
            self.say(f"{what} stopped: the keys drive")
            return
        program = station.program is not None
        if not program and station.algorithm is None:
            self.action_algorithm()
            return
        if not program and station.missing_sensors():
            self.say("the algorithm lacks a sensor: f fits the sensors it needs", lacks_sensor)
            return
        try:
            station.start()
        except (FsmError, ValueError) as exc:
            if program:  # a missing sensor takes a line each: the first says enough here
                self.say(f"cannot start: {exc.args[0].splitlines()[0]} (o sets the ports)")
            else:
                self.say(f"cannot start: {exc}")
            return
        self.say("")

    def action_fix_sensors(self) -> None:
        station = self.station
        program = station.program
        if program is not None:  # a program file chosen drives on start, not the algorithm
            self._fit_program(program)
            return
        if station.algorithm is None:
            self.say("choose an algorithm first (g)")
            return
        if station.missing_sensors() is None:
            self.say(f"the sensors already fit {station.algorithm.name}")
            return
        try:
            station.apply_algorithm_preset()
        except (SensorConfigError, FsmError, ValueError) as exc:
            self.say(f"cannot fit the sensors: {exc}")
            return
        ports = ", ".join(str(s) for s in station.sensors)
        self.say(f"sensors set for {station.algorithm.name}: {ports}; x starts it")

    def _fit_program(self, program: ProgramChoice) -> None:
        station = self.station
        if program.needs(station.sensors) is None or program.fit is None:
            self.say(f"the sensors already fit {program.name}")
            return
        fitted, cannot = program.fit(station.sensors)
        try:
            station.apply_sensors(fitted)
        except SensorConfigError as exc:
            self.say(f"cannot fit the sensors {program.name} reads: {exc}")
            return
        ports = ", ".join(str(s) for s in station.sensors)
        rest = f"; cannot fit: {cannot}" if cannot else "; x starts it"
        self.say(f"sensors set for {program.name}: {ports}{rest}")

    def action_unicode(self) -> None:
        self.post_message(ToggleUnicode())

    def set_unicode(self, unicode: bool) -> None:
        self._maze_view.set_unicode(unicode)
        self.refresh_views()

    def action_trail(self) -> None:
        view = self._maze_view
        view.set_trail(not view.trail)

    def action_maze(self, value: str | None = None, error: str = "") -> None:
        """Ask for a maze file and put it on the station (the robot starts over on it)."""
        from ..dialogs.path import PathDialog

        files = self.station.files
        if value is None:
            current = self.maze_path
            value = f"{files.shown(Path(current).parent)}/" if current else files.home()
            value = value.replace("~//", "~/")

        def chosen(path: str | None) -> None:
            if path is not None:
                self._load_maze(path)

        hint = "A maze file: the workbench text format, micromouse text or .maz, or mms."
        dialog = PathDialog(
            "Load a maze", hint, value=value, action="Load", error=error, note=files.note()
        )
        self.app.push_screen(dialog, chosen)

    def _load_maze(self, path: str) -> None:
        try:
            real = self.station.files.for_reading(path)
            maze = load_maze(real)
        except OutsideWorkspace as exc:
            self.action_maze(path, str(exc))
            return
        except MazeError as exc:
            problems = [str(p) for p in exc.problems]
            heading = [f"{len(problems)} problems in the file:"] if len(problems) > 1 else []
            self.action_maze(path, "\n".join(heading + problems))
            return
        self.station.load_maze(maze)
        self._maze_view.set_maze(maze)
        self._maze_view.clear_trail()
        self.post_message(MazeChanged(real))  # the app names the maze on the message line

    def action_editor(self) -> None:
        self.post_message(OpenScreen("editor"))

    def action_runs(self) -> None:
        self.post_message(OpenScreen("runs"))

    def action_fsm_editor(self) -> None:
        self.post_message(OpenScreen("fsm"))

    def action_labs(self) -> None:
        self.post_message(OpenScreen("labs"))

    def action_viple_ws(self) -> None:
        self.post_message(StartEndpoint("ws"))


#: the message line when the station is paused while a VIPLE program over the network drives
HELD_WHILE_PAUSED = (
    "paused: the VIPLE program's commands are held, not applied, until p resumes; "
    "it still gets the robot's readings"
)


def speed_held(driver: Driver) -> str:
    """Why the speed key changes nothing while ``driver`` (a live VIPLE program) drives."""
    return f"speed held at 1x while {driver} drives: its Timers count real time"


#: whether a message still holds of the station
StillTrue = Callable[[LabStation], bool]


def is_paused(station: LabStation) -> bool:
    return station.paused


def live_viple_drives(station: LabStation) -> bool:
    return station.live_viple is not None


def lacks_sensor(station: LabStation) -> bool:
    return station.driving is None and station.missing_sensors() is not None


def worded(notice: Notice, shown: Callable[[str | os.PathLike], str] = str) -> str:
    """What the message line says of something the station did on its own (``shown`` gives a
    path as the student sees it)."""
    if notice.kind == ALGORITHM_FAILED:
        return f"algorithm stopped: {notice.detail}"
    if notice.kind == PROGRAM_STOPPED:
        return f"program stopped at {notice.detail}"
    if notice.recording is not None:
        return record_words(notice.recording, shown)
    return "the robot is out: run finished (r resets the robot)"
