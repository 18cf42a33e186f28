"""The main screen: the maze with the robot, and around it everything a lab needs at a glance.

Layout: the maze view (most of the space) over the run status, a side panel with the key
legend, the sensor readings by port and the algorithm's live state, the message line and the
footer. Every action here calls the station; the screen only draws what the station reports.
"""

from __future__ import annotations

from pathlib import Path
from time import monotonic
from typing import ClassVar

from textual.app import ComposeResult
from textual.binding import Binding, BindingType
from textual.containers import Horizontal, Vertical
from textual.reactive import var
from textual.screen import Screen
from textual.widgets import Footer

from workbench.control.fsm import FsmError
from workbench.control.station import LabStation
from workbench.files.workspace import OutsideWorkspace
from workbench.sim.maze import MazeError
from workbench.sim.mazeio import load_maze
from workbench.sim.sensors import SensorConfigError
from workbench.sim.session import Snapshot

from ..compositor import LiveCompositor
from ..host import (
    FollowsUnicode,
    MazeChanged,
    OpenScreen,
    ShowsSnapshot,
    StartEndpoint,
    StationChanged,
    ToggleUnicode,
)
from ..widgets.algorithm_state import AlgorithmState
from ..widgets.key_legend import KeyLegend
from ..widgets.maze_view import MazeView
from ..widgets.message_bar import MessageBar
from ..widgets.run_status import RunStatus
from ..widgets.sensor_readings import SensorReadings

#: how often the text panels follow a running robot (the maze view follows every tick)
PANEL_HZ = 4.0


class MainScreen(ShowsSnapshot, FollowsUnicode, Screen[None]):
    """Drive, watch and set up the robot."""

    # the keys pressed again and again while driving are priority bindings: the screen takes
    # them before the focused widget (the transition log, which has no use for them) would, so
    # a key press runs its action at once instead of bubbling up through the side panel
    BINDINGS: ClassVar[list[BindingType]] = [
        Binding("w", "drive('w')", "Forward", show=False, priority=True, id="drive.forward"),
        Binding("a", "drive('a')", "Left", show=False, priority=True, id="drive.left"),
        Binding("s", "drive('s')", "Backward", show=False, priority=True, id="drive.backward"),
        Binding("d", "drive('d')", "Right", show=False, priority=True, id="drive.right"),
        Binding("space", "drive('space')", "Stop", show=False, priority=True, id="drive.stop"),
        Binding("p", "pause", "Pause", priority=True, id="sim.pause"),
        Binding("n", "step", "Step", priority=True, id="sim.step"),
        Binding("plus,equals_sign", "speed", "Speed", key_display="+", id="sim.speed"),
        Binding("r", "reset", "Reset", id="sim.reset"),
        Binding("o", "sensors", "Ports", id="panel.sensors"),
        Binding("g", "algorithm", "Algorithm", id="panel.algorithm"),
        Binding("x", "run_algorithm", "Run", id="algorithm.run"),
        Binding("f", "fix_sensors", "Fix sensors", show=False, id="algorithm.fix"),
        Binding("u", "unicode", "Unicode", show=False, id="view.unicode"),
        Binding("t", "trail", "Trail", show=False, id="view.trail"),
        Binding("m", "maze", "Maze", show=False, id="maze.load"),
        Binding("e", "editor", "Editor", show=False, id="screen.editor"),
        Binding("R", "runs", "Runs", show=False, id="screen.runs"),
        Binding("l", "labs", "Labs", show=False, id="screen.labs"),
        Binding("v", "viple_ws", "WebSocket", show=False, id="viple.ws"),
    ]

    #: the last snapshot drawn (per-tick state: never repaints by itself)
    snapshot: var[Snapshot | None] = var(None)

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
        self._compositor = LiveCompositor()
        self.station = station
        self._ready = False
        self._unicode = unicode
        self._trail = trail
        self._controller: object = None
        self._moment: tuple[object, ...] = ()
        self._panels_at = 0.0

    def compose(self) -> ComposeResult:
        station = self.station
        self._maze_view = MazeView(
            station.maze, unicode=self._unicode, trail=self._trail, id="maze"
        )
        self._run_status = RunStatus(id="run")
        self._legend = KeyLegend(station.profile, id="legend")
        self._readings = SensorReadings(id="readings")
        self._algorithm = AlgorithmState(id="algorithm")
        self._message = MessageBar(self.who, id="message")
        with Horizontal(id="body"):
            with Vertical(id="stage"):
                yield self._maze_view
                yield self._run_status
            with Vertical(id="side"):
                yield self._legend
                yield self._readings
                yield self._algorithm
        yield self._message
        yield Footer(compact=True, show_command_palette=False)

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
        if station.controller is not self._controller:
            self._controller = station.controller
            if station.controller is not None:
                self._maze_view.clear_trail()  # a new run starts from the start block
        self._maze_view.show(snapshot, station.session.world.cell)
        # the text panels follow at PANEL_HZ while the robot runs (every byte counts over SSH);
        # at once when paused (steps, snapshots) and when who drives or the state changes
        now = monotonic()
        moment = (
            station.paused,
            station.message,
            snapshot.driver,
            snapshot.state,
            station.connection,
        )
        if station.paused or moment != self._moment or now - self._panels_at >= 1 / PANEL_HZ:
            self._moment = moment
            self._panels_at = now
            self._readings.show(snapshot, station.profile)
            self._run_status.show(snapshot, station, unicode)
            self._algorithm.show(station, unicode)
            self._message.message = station.message

    def refresh_views(self) -> None:
        """Redraw after an action: the app draws every screen that shows the station, this one
        and the dialogs over it."""
        self.post_message(StationChanged())

    def say(self, message: str) -> None:
        self.station.message = message
        self.refresh_views()

    # -- actions -------------------------------------------------------------------------------
    def action_drive(self, key: str) -> None:
        station = self.station
        station.message = ""
        station.key(key)
        if station.paused:
            self.refresh_views()
        # else the next tick draws it, within 1/20 s, with the robot already moving: drawing
        # now as well would draw every key twice while a student drives

    def action_pause(self) -> None:
        paused = self.station.toggle_pause()
        self.say("paused: n steps, p resumes" if paused else "")

    def action_step(self) -> None:
        station = self.station
        station.pause()
        station.step(station.session.every)
        self.refresh_views()

    def action_speed(self) -> None:
        self.station.pacer.next_speed()
        self.refresh_views()

    def action_reset(self) -> None:
        self.station.reset_robot()
        self._maze_view.clear_trail()
        self.refresh_views()

    def action_sensors(self) -> None:
        from ..dialogs.sensor_ports import SensorPortsModal

        self.app.push_screen(SensorPortsModal(self.station))

    def action_algorithm(self) -> None:
        from ..dialogs.algorithm import AlgorithmModal

        self.app.push_screen(AlgorithmModal(self.station))

    def action_run_algorithm(self) -> None:
        station = self.station
        if station.controller is not None:
            station.stop_algorithm("stopped")
            self.say("algorithm stopped: the keys drive")
            return
        if station.algorithm is None:
            self.action_algorithm()
            return
        missing = station.missing_sensors()
        if missing:
            self.say("the algorithm lacks a sensor: f fits the sensors it needs")
            return
        try:
            station.start_algorithm()
        except (FsmError, ValueError) as exc:
            self.say(f"cannot start: {exc}")
            return
        self.refresh_views()

    def action_fix_sensors(self) -> None:
        station = self.station
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
            self.action_maze(path, "\n".join(str(p) for p in exc.problems))
            return
        self.station.load_maze(maze)
        self._maze_view.set_maze(maze)
        self._maze_view.clear_trail()
        self.station.message = f"the robot is on {maze.name}"
        self.post_message(MazeChanged(real))

    def action_editor(self) -> None:
        self.post_message(OpenScreen("editor"))

    def action_runs(self) -> None:
        self.post_message(OpenScreen("runs"))

    def action_labs(self) -> None:
        self.post_message(OpenScreen("labs"))

    def action_viple_ws(self) -> None:
        self.post_message(StartEndpoint("ws"))
