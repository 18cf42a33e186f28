"""What every key does, in one table: the help screen and the command palette read it.

Each binding of the app and its screens has an id; :data:`COMMANDS` gives it a group, a title
for the command palette and a sentence for the help screen. :class:`WorkbenchCommands` offers
the bindings of the screen the palette was opened on as commands.
"""

from __future__ import annotations

from collections.abc import Awaitable, Callable, Iterator
from dataclasses import dataclass
from functools import partial

from textual.binding import Binding
from textual.command import DiscoveryHit, Hit, Hits, Provider
from textual.dom import DOMNode


@dataclass(frozen=True)
class CommandInfo:
    group: str
    title: str
    explanation: str


COMMANDS: dict[str, CommandInfo] = {
    info_id: CommandInfo(*info)
    for info_id, info in {
        "drive.forward": (
            "Drive",
            "forward",
            "Drive forward, as the course's key program does for this profile.",
        ),
        "drive.left": ("Drive", "left", "Turn left (unity: Turn by Degree -90; web: spin)."),
        "drive.backward": ("Drive", "backward", "Drive backward."),
        "drive.right": ("Drive", "right", "Turn right (unity: Turn by Degree 90; web: spin)."),
        "drive.stop": ("Drive", "stop", "Stop the motors."),
        "sim.pause": (
            "Simulation",
            "pause / resume",
            "Pause or resume the simulation (keys still queue commands while paused).",
        ),
        "sim.step": (
            "Simulation",
            "single step",
            "Pause, then advance one control tick (1/20 s of simulated time).",
        ),
        "sim.speed": (
            "Simulation",
            "speed",
            "Cycle the speed: 1x, 2x, 4x, 10x, max (as fast as the machine allows).",
        ),
        "sim.reset": (
            "Simulation",
            "reset robot",
            "Robot back to the start, stopped, like the Unity simulator's reset button; "
            "a running algorithm stops and the run is kept in the runs list.",
        ),
        "panel.sensors": (
            "Set-up",
            "sensor ports",
            "Open the sensor port panel: kinds, port numbers, mounts, presets, live readings.",
        ),
        "panel.algorithm": (
            "Set-up",
            "algorithm",
            "Choose a built-in algorithm or load a YAML FSM file or a VIPLE program "
            "(.viple, .xml); edit its parameters.",
        ),
        "algorithm.run": (
            "Algorithm",
            "start / stop algorithm",
            "Start the chosen algorithm or VIPLE program from the start block (a new run), "
            "or stop it.",
        ),
        "program.keys": (
            "Algorithm",
            "keys to a program",
            "While a VIPLE program drives, w a s d, the arrows, the digits and letters the "
            "screen does not use go to its Key Press events; a key counts as released 0.75 s "
            "after it stops repeating, or when another key comes. Space stops the program.",
        ),
        "algorithm.fix": (
            "Algorithm",
            "fit the sensors it needs",
            "When the algorithm lacks a sensor: give the robot the sensors it reads "
            "(the algorithm's preset).",
        ),
        "view.unicode": (
            "View",
            "ASCII / Unicode",
            "Draw the maze with plain ASCII (any terminal) or Unicode lines and arrows.",
        ),
        "view.trail": ("View", "trail", "Show or hide the blocks the robot has driven through."),
        "maze.load": (
            "Set-up",
            "load a maze",
            "Put a maze file on the bench (the robot starts over on it, same profile).",
        ),
        "screen.editor": (
            "Screens",
            "maze editor",
            "Edit the maze: walls, start, exits, new, generate, validate, save.",
        ),
        "screen.runs": (
            "Screens",
            "runs",
            "Compare the last runs side by side; replay a recorded run.",
        ),
        "screen.labs": (
            "Screens",
            "labs",
            "The lab exercises: instructions, set-up, live objectives, questions, sign-off.",
        ),
        "viple.ws": (
            "VIPLE",
            "connect over WebSocket",
            "Connect to VIPLE's WebSocket server (the Web Simulator's role) at --ws-url or "
            "ws://localhost:8124/; it tries every second until the VIPLE program runs.",
        ),
        "labs.close": ("Labs", "back", "Back to the maze (the exercise keeps being checked)."),
        "labs.setup": (
            "Labs",
            "set up the exercise",
            "Put the exercise's profile, maze, sensors and controller on the bench.",
        ),
        "labs.signoff": (
            "Labs",
            "instructor sign-off",
            "The instructor signs the exercise off with their passphrase; then change driver.",
        ),
        "app.help": ("App", "help", "This help: every key and what it does."),
        "app.commands": ("App", "command palette", "Search every command by name."),
        "app.quit": ("App", "quit", "Quit the workbench (ctrl+c does not quit)."),
        "dialog.close": ("Dialog", "close", "Close this dialog."),
        "sensors.apply": (
            "Sensor ports",
            "apply",
            "Apply the rows to the live robot (nothing changes if a row is wrong).",
        ),
        "sensors.add": ("Sensor ports", "add a row", "Add a sensor row."),
        "algorithm.start": (
            "Algorithm dialog",
            "start",
            "Start the chosen algorithm with the parameters shown.",
        ),
        "algorithm.defaults": (
            "Algorithm dialog",
            "default parameters",
            "Put every parameter back to its default for this profile.",
        ),
    }.items()
}


def key_display(node: DOMNode, binding: Binding) -> str:
    """How the key is written on screen (``spc`` -> ``space``, ``ctrl+q`` -> ``^q``)."""
    if binding.key_display:
        return binding.key_display
    return node.app.get_key_display(binding)


def describe(node: DOMNode, binding: Binding) -> CommandInfo:
    """The palette entry of a binding: from :data:`COMMANDS`, else from the binding itself."""
    info = COMMANDS.get(binding.id or "")
    if info is not None:
        return info
    group = type(node).__name__.removesuffix("Screen") or "App"
    title = binding.description or binding.action
    return CommandInfo(group, title.lower(), binding.tooltip or binding.description)


def bindings_with_ids(node: DOMNode) -> Iterator[Binding]:
    """The node's bindings that have an id, once each, in declared order."""
    seen: set[str] = set()
    for _key, binding in node._bindings:
        if (
            binding.id
            and binding.id not in seen
            and (binding.description or binding.id in COMMANDS)
        ):
            seen.add(binding.id)
            yield binding


class WorkbenchCommands(Provider):
    """The key bindings of the current screen and of the app as command palette commands."""

    def _commands(self) -> list[tuple[str, str, Callable[[], Awaitable[object]]]]:
        out = []
        seen: set[str] = set()
        for node in (self.screen, self.app):
            for binding in bindings_with_ids(node):
                assert binding.id is not None
                if binding.id in seen or binding.id == "app.commands":
                    continue
                seen.add(binding.id)
                info = describe(node, binding)
                title = f"{info.group}: {info.title}"
                help_text = f"key {key_display(node, binding)}: {info.explanation}"
                out.append((title, help_text, partial(self.app.run_action, binding.action, node)))
        return out

    async def discover(self) -> Hits:
        for title, help_text, run in self._commands():
            yield DiscoveryHit(title, run, help=help_text)

    async def search(self, query: str) -> Hits:
        matcher = self.matcher(query)
        for title, help_text, run in self._commands():
            score = matcher.match(title)
            if score > 0:
                yield Hit(score, matcher.highlight(title), run, help=help_text)
