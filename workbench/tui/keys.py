"""What every key does, in one table: the screens' bindings, the help screen, the command
palette, the footer and the key legends beside the editor's and the replay's maze are all made
from :data:`KEY_TABLE`.

Each entry has an id (``group.what``); a screen lists the ids it answers with
:func:`bindings` (the screens the help explains take theirs from the lists here, which the help
reads). The drive keys' effect in each profile's key program (the legend beside the main
screen's maze) comes from ``control/manual.py``, which the drive entries point to.
"""

from __future__ import annotations

import string
from dataclasses import dataclass

from textual.binding import Binding

from workbench.control.manual import KEY_NAMES


@dataclass(frozen=True)
class Key:
    """One key of the workbench: which keys, which action, and how it is explained."""

    #: the key names, comma-separated, as Textual writes them
    keys: str
    #: the action; ``{key}`` in it makes one binding per key, each naming its key
    action: str
    #: the footer's word for it
    label: str
    #: the help's section and the palette's prefix
    group: str
    #: the palette's name for it
    title: str
    #: the help's sentence
    explanation: str
    show: bool = True
    #: taken before the focused widget sees the key
    priority: bool = False
    #: how the key is written on screen, when not Textual's own way
    display: str | None = None
    #: the footer's priority where not every key fits: lower ranks stay longest
    rank: int = 2


KEY_TABLE: dict[str, Key] = {
    "app.quit": Key(
        "ctrl+q",
        "quit",
        "Quit",
        "App",
        "quit",
        "Quit the workbench (ctrl+c does not quit).",
        priority=True,
        rank=1,
    ),
    "app.help": Key(
        "question_mark",
        "help",
        "Help",
        "App",
        "help",
        "This help: every key and what it does.",
        display="?",
        rank=0,
    ),
    "app.commands": Key(
        "ctrl+p",
        "command_palette",
        "Commands",
        "App",
        "command palette",
        "Search every command by name.",
        show=False,
        priority=True,
    ),
    "drive.forward": Key(
        "w",
        "drive('w')",
        "Forward",
        "Drive",
        KEY_NAMES["w"],
        "Drive forward, as the course's key program does for this profile.",
        show=False,
        priority=True,
    ),
    "drive.left": Key(
        "a",
        "drive('a')",
        "Left",
        "Drive",
        KEY_NAMES["a"],
        "Turn left (unity: Turn by Degree -90; web: spin).",
        show=False,
        priority=True,
    ),
    "drive.backward": Key(
        "s",
        "drive('s')",
        "Backward",
        "Drive",
        KEY_NAMES["s"],
        "Drive backward.",
        show=False,
        priority=True,
    ),
    "drive.right": Key(
        "d",
        "drive('d')",
        "Right",
        "Drive",
        KEY_NAMES["d"],
        "Turn right (unity: Turn by Degree 90; web: spin).",
        show=False,
        priority=True,
    ),
    "drive.stop": Key(
        "space",
        "drive('space')",
        "Stop",
        "Drive",
        KEY_NAMES["space"],
        "Stop the motors.",
        show=False,
        priority=True,
    ),
    "sim.pause": Key(
        "p",
        "pause",
        "Pause",
        "Simulation",
        "pause / resume",
        "Pause or resume the simulation (keys still queue commands while paused).",
        priority=True,
    ),
    "sim.step": Key(
        "n",
        "step",
        "Step",
        "Simulation",
        "single step",
        "Pause, then advance one control tick (1/20 s of simulated time).",
        priority=True,
        rank=4,
    ),
    "sim.speed": Key(
        "plus,equals_sign",
        "speed",
        "Speed",
        "Simulation",
        "speed",
        "Cycle the speed: 1x, 2x, 4x, 10x, max (as fast as the machine allows).",
        display="+",
        rank=3,
    ),
    "sim.reset": Key(
        "r",
        "reset",
        "Reset",
        "Simulation",
        "reset robot",
        "Robot back to the start, stopped, like the Unity simulator's reset button; a running "
        "algorithm stops and the run is kept in the runs list.",
    ),
    "panel.sensors": Key(
        "o",
        "sensors",
        "Ports",
        "Set-up",
        "sensor ports",
        "Open the sensor port panel: kinds, port numbers, mounts, presets, live readings.",
        rank=3,
    ),
    "panel.algorithm": Key(
        "g",
        "algorithm",
        "Algorithm",
        "Set-up",
        "algorithm",
        "Choose a built-in algorithm or load a YAML FSM file or a VIPLE program "
        "(.viple, .xml); edit its parameters.",
    ),
    "algorithm.run": Key(
        "x",
        "run_algorithm",
        "Run",
        "Algorithm",
        "start / stop algorithm",
        "Start the chosen algorithm or VIPLE program from the start block (a new run), or stop it.",
    ),
    "program.keys": Key(
        "up,down,left,right",
        "program_key('{key}')",
        "Keys to the program",
        "Algorithm",
        "keys to a program",
        "While a VIPLE program drives, w a s d, the arrows, the digits and letters the screen "
        "does not use go to its Key Press events; a key counts as released 0.75 s after it "
        "stops repeating, or when another key comes. Space stops the program; p, r and the "
        "screen's other keys stay the workbench's (ctrl+k sends them to the program too).",
        show=False,
        priority=True,
        display="arrows",
    ),
    "program.all_keys": Key(
        "ctrl+k",
        "all_keys_to_program",
        "All keys",
        "Algorithm",
        "all keys to a program",
        "While a VIPLE program drives: every key, space, p and r too, goes to the program "
        "until ctrl+k gives the keys back; only ctrl+k and ctrl+q stay the workbench's.",
        show=False,
        priority=True,
        display="^k",
    ),
    "program.keys_back": Key(
        "ctrl+k",
        "keys_back",
        "Keys back",
        "Algorithm",
        "keys back to the workbench",
        "After ctrl+k sent every key to a program: the keys are the workbench's again.",
        priority=True,
        display="^k",
    ),
    "algorithm.fix": Key(
        "f",
        "fix_sensors",
        "Fix sensors",
        "Algorithm",
        "fit the sensors it needs",
        "When the algorithm lacks a sensor: give the robot the sensors it reads (the "
        "algorithm's preset).",
        show=False,
    ),
    "view.unicode": Key(
        "u",
        "unicode",
        "Unicode",
        "View",
        "ASCII / Unicode",
        "Draw the maze with plain ASCII (any terminal) or Unicode lines and arrows.",
        show=False,
    ),
    "view.trail": Key(
        "t",
        "trail",
        "Trail",
        "View",
        "trail",
        "Show or hide the blocks the robot has driven through.",
        show=False,
    ),
    "maze.load": Key(
        "m",
        "maze",
        "Maze",
        "Set-up",
        "load a maze",
        "Put a maze file on the bench (the robot starts over on it, same profile).",
        rank=1,
    ),
    "screen.editor": Key(
        "e",
        "editor",
        "Editor",
        "Screens",
        "maze editor",
        "Edit the maze: walls, start, exits, new, generate, validate, save.",
        rank=1,
    ),
    "screen.fsm": Key(
        "F",
        "fsm_editor",
        "FSM",
        "Screens",
        "FSM editor",
        "Write your own state machine: its YAML with every problem as you type, its diagram, "
        "forms to add states and transitions; save it and run it on the robot.",
    ),
    "fsm.save": Key(
        "ctrl+s",
        "save",
        "Save",
        "FSM editor",
        "save the FSM",
        "Save the file (undo is kept).",
        priority=True,
        display="^s",
    ),
    "fsm.run": Key(
        "ctrl+r",
        "run",
        "Run",
        "FSM editor",
        "save and run the FSM",
        "Save the file and start it on the robot; the diagram lights the state it is in.",
        priority=True,
        display="^r",
    ),
    "fsm.state": Key(
        "ctrl+n",
        "add_state",
        "State",
        "FSM editor",
        "add a state",
        "Add a state through a form (its name and actions).",
        priority=True,
        display="^n",
    ),
    "fsm.transition": Key(
        "ctrl+b",
        "add_transition",
        "Transition",
        "FSM editor",
        "add a transition",
        "Add a transition through a form (from, to, condition, assignments).",
        priority=True,
        display="^b",
    ),
    "fsm.diagram": Key(
        "ctrl+t",
        "toggle_diagram",
        "Diagram",
        "FSM editor",
        "text or diagram",
        "Below 100 columns: show the diagram instead of the text, or the text again.",
        priority=True,
        display="^t",
    ),
    "fsm.leave": Key(
        "escape",
        "leave",
        "Leave",
        "FSM editor",
        "leave the FSM editor",
        "Leave the editor; unsaved changes are asked about first.",
        priority=True,
    ),
    "screen.runs": Key(
        "R",
        "runs",
        "Runs",
        "Screens",
        "runs",
        "Compare the last runs side by side; replay a recorded run.",
        rank=1,
    ),
    "screen.labs": Key(
        "l",
        "labs",
        "Labs",
        "Screens",
        "labs",
        "The lab exercises: instructions, set-up, live objectives, questions, sign-off.",
        rank=1,
    ),
    "viple.ws": Key(
        "v",
        "viple_ws",
        "WebSocket",
        "VIPLE",
        "connect over WebSocket",
        "Connect to VIPLE's WebSocket server (the Web Simulator's role) at --ws-url or "
        "ws://localhost:8124/; it tries every second until the VIPLE program runs.",
        show=False,
    ),
    "editor.up": Key(
        "up", "move(0, -1)", "Cursor up", "Maze editor", "cursor up", "Cursor up.", show=False
    ),
    "editor.down": Key(
        "down",
        "move(0, 1)",
        "Cursor down",
        "Maze editor",
        "cursor down",
        "Cursor down.",
        show=False,
    ),
    "editor.left": Key(
        "left",
        "move(-1, 0)",
        "Cursor left",
        "Maze editor",
        "cursor left",
        "Cursor left.",
        show=False,
    ),
    "editor.right": Key(
        "right",
        "move(1, 0)",
        "Cursor right",
        "Maze editor",
        "cursor right",
        "Cursor right.",
        show=False,
    ),
    "editor.wall": Key(
        "space",
        "toggle_wall",
        "Wall",
        "Maze editor",
        "wall",
        "Turn the block under the cursor into wall or floor (or click a block).",
    ),
    "editor.start": Key(
        "s",
        "start",
        "Start",
        "Maze editor",
        "start",
        "Put the start on the cursor; press again to turn its heading.",
    ),
    "editor.exit": Key(
        "x", "exit", "Exit", "Maze editor", "exit", "Add or remove an exit at the cursor."
    ),
    "editor.undo": Key(
        "ctrl+z", "undo", "Undo", "Maze editor", "undo", "Undo an edit.", display="^z"
    ),
    "editor.redo": Key(
        "ctrl+y",
        "redo",
        "Redo",
        "Maze editor",
        "redo",
        "Redo an undone edit.",
        show=False,
        display="^y",
    ),
    "editor.new": Key(
        "n",
        "new",
        "New",
        "Maze editor",
        "new",
        "Start an empty maze of a size you type.",
        show=False,
    ),
    "editor.generate": Key(
        "g",
        "generate",
        "Generate",
        "Maze editor",
        "generate",
        "Generate a maze from a seed (perfect or braid, with exits or none).",
        show=False,
    ),
    "editor.save": Key(
        "ctrl+s",
        "save",
        "Save",
        "Maze editor",
        "save",
        "Save to the maze's file (asks for a path the first time).",
        display="^s",
    ),
    "editor.save_as": Key(
        "a", "save_as", "Save as", "Maze editor", "save as", "Save to a new path.", show=False
    ),
    "editor.next_problem": Key(
        "p",
        "next_problem",
        "Next problem",
        "Maze editor",
        "next problem",
        "Move the cursor to the next problem in the list.",
        show=False,
    ),
    "editor.unicode": Key(
        "u",
        "unicode",
        "Unicode",
        "Maze editor",
        "unicode",
        "Draw the maze in plain ASCII or with Unicode lines.",
        show=False,
    ),
    "editor.leave": Key(
        "escape",
        "leave",
        "Back",
        "Maze editor",
        "back",
        "Leave the editor; a changed valid maze goes to the robot.",
        rank=1,
    ),
    "runs.replay": Key(
        "enter",
        "replay",
        "Replay",
        "Runs",
        "replay",
        "Replay the selected run from its record.",
        priority=True,  # before the table's own enter, which would hide it from the key bar
        rank=1,
    ),
    "runs.open": Key(
        "o",
        "open",
        "Open record",
        "Runs",
        "open record",
        "Replay any run record (.jsonl) by its path.",
    ),
    "runs.scope": Key(
        "a",
        "scope",
        "This/all mazes",
        "Runs",
        "this maze or all",
        "Show the runs on this maze and profile, or the runs on every maze by maze and profile.",
    ),
    "runs.unicode": Key(
        "u", "unicode", "Unicode", "Runs", "unicode", "Plain ASCII or Unicode marks.", show=False
    ),
    "runs.leave": Key("escape", "leave", "Back", "Runs", "back", "Back to the workbench.", rank=1),
    "runs.picture": Key(
        "p",
        "picture('path')",
        "Picture",
        "Runs",
        "picture of the run",
        "Save the selected run's path on its maze as a picture (SVG) in pictures/.",
    ),
    "runs.plot": Key(
        "t",
        "picture('time')",
        "Plot",
        "Runs",
        "plot of the run over time",
        "Save the selected run's sensors, wheel powers and states over time (SVG) in pictures/.",
        show=False,
    ),
    "runs.compare": Key(
        "c",
        "picture('compare')",
        "Side by side",
        "Runs",
        "runs side by side",
        "Save the recorded runs on this maze (the last 12) side by side with their figures "
        "(SVG) in pictures/.",
        show=False,
    ),
    "replay.step": Key("right", "step(1)", "Step", "Replay", "step", "Forward one control tick."),
    "replay.back": Key("left", "step(-1)", "Back", "Replay", "back", "Back one control tick."),
    "replay.step10": Key(
        "pagedown", "step(10)", "+10", "Replay", "+10", "Forward ten ticks.", show=False
    ),
    "replay.back10": Key(
        "pageup", "step(-10)", "-10", "Replay", "-10", "Back ten ticks.", show=False
    ),
    "replay.play": Key(
        "space",
        "play",
        "Play/pause",
        "Replay",
        "play/pause",
        "Play the run at the speed shown, or pause it.",
    ),
    "replay.faster": Key(
        "plus,equals_sign", "faster", "Faster", "Replay", "faster", "Play faster.", display="+"
    ),
    "replay.slower": Key(
        "minus", "slower", "Slower", "Replay", "slower", "Play slower.", display="-"
    ),
    "replay.first": Key("home", "first", "First", "Replay", "first", "The first tick.", show=False),
    "replay.last": Key("end", "last", "Last", "Replay", "last", "The last tick.", show=False),
    "replay.unicode": Key(
        "u",
        "unicode",
        "Unicode",
        "Replay",
        "unicode",
        "Draw the maze in plain ASCII or with Unicode lines.",
        show=False,
    ),
    "replay.leave": Key("escape", "leave", "Back", "Replay", "back", "Back to the runs.", rank=1),
    "replay.picture": Key(
        "p",
        "picture('path')",
        "Picture",
        "Replay",
        "picture of the run",
        "Save the run's path on its maze, with the sensors' beams at this tick, as a picture "
        "(SVG) in pictures/.",
    ),
    "replay.plot": Key(
        "t",
        "picture('time')",
        "Plot",
        "Replay",
        "plot of the run over time",
        "Save the run's sensors, wheel powers and states over time (SVG) in pictures/.",
        show=False,
    ),
    "labs.close": Key(
        "escape",
        "close",
        "Back",
        "Labs",
        "back",
        "Back to the maze (the exercise keeps being checked).",
    ),
    "labs.setup": Key(
        "a",
        "apply_setup",
        "Set up",
        "Labs",
        "set up the exercise",
        "Put the exercise's profile, maze, sensors and controller on the bench and begin a "
        "new attempt (over work not yet counted it asks first).",
    ),
    "labs.signoff": Key(
        "i",
        "sign_off",
        "Sign off",
        "Labs",
        "instructor sign-off",
        "At a workbench of your own, the instructor signs the exercise off here with their "
        "passphrase, then you change driver; in a lab server session, press r instead.",
    ),
    "labs.ready": Key(
        "r",
        "ready",
        "Ready",
        "Labs",
        "ready for sign-off",
        "Ask an instructor to sign the exercise off: it joins the sign-off queue, and the "
        "screen shows your place, a decline's note or the sign-off.",
    ),
    "console.open": Key(
        "enter",
        "open_entry",
        "Open",
        "Console",
        "open the request",
        "Open the chosen request: the objectives, their evidence, the run and the sign-off.",
    ),
    "console.grid": Key(
        "g",
        "grid",
        "Grid",
        "Console",
        "students by exercises",
        "Show every student in every exercise: passed, waiting for sign-off or signed off.",
        rank=1,
    ),
    "grid.lab": Key(
        "l", "next_lab", "Next lab", "Console", "next lab", "Show the next lab's exercises."
    ),
    "grid.leave": Key(
        "escape", "leave", "Back", "Console", "back", "Back to the queue and the class.", rank=1
    ),
    "console.replay": Key(
        "p",
        "replay",
        "Replay",
        "Console",
        "replay the evidence run",
        "Replay the run the objectives rest on, in the maze view.",
    ),
    "console.picture": Key(
        "ctrl+g",
        "picture",
        "Picture",
        "Console",
        "picture of the evidence run",
        "Save the evidence run's path on its maze as a picture (SVG) in pictures/ in the "
        "current folder.",
        priority=True,  # (typed into the note or the passphrase otherwise)
    ),
    "console.sign": Key(
        "ctrl+s",
        "sign",
        "Sign",
        "Console",
        "sign off",
        "Sign the exercise off with your key (your passphrase is typed here, in your own session).",
        priority=True,
    ),
    "console.decline": Key(
        "ctrl+d",
        "decline",
        "Decline",
        "Console",
        "decline",
        "Decline the request; the note says what to do and the student sees it.",
        priority=True,
    ),
    "dialog.close": Key("escape", "close", "Close", "Dialog", "close", "Close this dialog."),
    "sensors.add": Key(
        "ctrl+n", "add_row", "Add row", "Sensor ports", "add a row", "Add a sensor row."
    ),
    "algorithm.defaults": Key(
        "ctrl+d",
        "defaults",
        "Defaults",
        "Algorithm dialog",
        "default parameters",
        "Put every parameter back to its default for this profile.",
    ),
    "algorithm.edit": Key(
        "E",
        "edit_fsm",
        "Edit",
        "Algorithm dialog",
        "edit the FSM",
        "Open the FSM editor on the file typed, the chosen algorithm's, or a new machine.",
    ),
    "dialog.cancel": Key("escape", "cancel", "Cancel", "Dialog", "cancel", "Cancel."),
    "unsaved.save": Key("s", "choose('save')", "Save", "Unsaved changes", "save", "Save."),
    "unsaved.discard": Key(
        "d", "choose('discard')", "Discard", "Unsaved changes", "discard", "Discard."
    ),
    "unsaved.cancel": Key(
        "c,escape", "choose('cancel')", "Cancel", "Unsaved changes", "cancel", "Cancel."
    ),
    "confirm.yes": Key("y", "answer(True)", "Yes", "Dialog", "yes", "Yes: go ahead."),
    "confirm.no": Key("n", "answer(False)", "No", "Dialog", "no", "No: leave things as they are."),
    "pair.agree": Key(
        "y",
        "choose(True)",
        "Pair",
        "Confirm the pair",
        "sign for the pair",
        "The partner worked on it and agrees: sign for both.",
    ),
    "pair.alone": Key(
        "n",
        "choose(False)",
        "Alone",
        "Confirm the pair",
        "sign for the student alone",
        "Sign for the student alone: the partner's gradebook row is left as it is.",
    ),
    "help.close": Key(
        "escape,question_mark,q", "close", "Close", "Dialog", "close", "Close this dialog."
    ),
}


def bindings(*ids: str) -> list[Binding]:
    """The bindings of the keys ``ids``, in that order (a screen's ``BINDINGS``)."""
    made = []
    for key_id in ids:
        key = KEY_TABLE[key_id]
        each = key.keys.split(",") if "{key}" in key.action else [key.keys]
        for name in each:
            made.append(
                Binding(
                    name,
                    key.action.replace("{key}", name),
                    key.label,
                    show=key.show,
                    key_display=key.display,
                    priority=key.priority,
                    id=key_id,
                )
            )
    return made


#: the keys of the app itself, on every screen
APP_KEY_IDS = ("app.quit", "app.help", "app.commands")
#: the main screen's keys, in the footer's order
MAIN_KEY_IDS = (
    "drive.forward",
    "drive.left",
    "drive.backward",
    "drive.right",
    "drive.stop",
    "sim.pause",
    "sim.step",
    "sim.speed",
    "sim.reset",
    "panel.sensors",
    "panel.algorithm",
    "algorithm.run",
    "algorithm.fix",
    "view.unicode",
    "view.trail",
    "maze.load",
    "screen.editor",
    "screen.runs",
    "screen.labs",
    "viple.ws",
    "screen.fsm",
    "program.keys",
    "program.all_keys",
    "program.keys_back",
)
#: the maze editor's keys
EDITOR_KEY_IDS = (
    "editor.up",
    "editor.down",
    "editor.left",
    "editor.right",
    "editor.wall",
    "editor.start",
    "editor.exit",
    "editor.undo",
    "editor.redo",
    "editor.new",
    "editor.generate",
    "editor.save",
    "editor.save_as",
    "editor.next_problem",
    "editor.unicode",
    "editor.leave",
)
#: the FSM editor's keys
FSM_EDITOR_KEY_IDS = (
    "fsm.save",
    "fsm.run",
    "fsm.state",
    "fsm.transition",
    "fsm.diagram",
    "fsm.leave",
)
#: the runs screen's keys
RUNS_KEY_IDS = (
    "runs.replay",
    "runs.open",
    "runs.scope",
    "runs.unicode",
    "runs.leave",
    "runs.picture",
    "runs.plot",
    "runs.compare",
)
#: the replay screen's keys
REPLAY_KEY_IDS = (
    "replay.step",
    "replay.back",
    "replay.step10",
    "replay.back10",
    "replay.play",
    "replay.faster",
    "replay.slower",
    "replay.first",
    "replay.last",
    "replay.unicode",
    "replay.leave",
    "replay.picture",
    "replay.plot",
)
#: the labs screen's keys
LABS_KEY_IDS = ("labs.close", "labs.setup", "labs.ready", "labs.signoff")
#: the help's sections of screen keys: heading, and the keys in the order explained
HELP_SECTIONS: tuple[tuple[str, tuple[str, ...]], ...] = (
    ("Workbench", MAIN_KEY_IDS + APP_KEY_IDS),
    ("Labs (l)", LABS_KEY_IDS),
    ("Maze editor (e)", EDITOR_KEY_IDS),
    ("FSM editor (F)", FSM_EDITOR_KEY_IDS),
    ("Runs (R)", RUNS_KEY_IDS),
    ("Replay (enter on a run)", REPLAY_KEY_IDS),
)

#: letters and digits a running VIPLE program gets besides the drive keys and the arrows: the
#: ones the main screen has no key of its own for
PROGRAM_KEYS = frozenset(
    set(string.ascii_lowercase + string.digits)
    - {name for key_id in MAIN_KEY_IDS for name in KEY_TABLE[key_id].keys.split(",")}
)

#: how a key is written in a legend, where Textual's name is long
LEGEND_NAMES = {"escape": "esc", "pageup": "pgup", "pagedown": "pgdn"}


@dataclass(frozen=True)
class LegendEntry:
    """Keys of the table as a screen's legend shows them: ``keys what``."""

    #: the table's keys it stands for
    ids: tuple[str, ...]
    #: how they are written (default: each one's display or short name, joined by ``/``)
    keys: str = ""
    #: what they do (default: the first one's title)
    what: str = ""

    def __post_init__(self) -> None:
        unknown = [key_id for key_id in self.ids if key_id not in KEY_TABLE]
        if not self.ids or unknown:
            raise KeyError(f"a legend entry names keys not in the table: {unknown or 'none'}")

    def text(self) -> str:
        entries = [KEY_TABLE[key_id] for key_id in self.ids]
        keys = self.keys or "/".join(
            entry.display or LEGEND_NAMES.get(entry.keys, entry.keys) for entry in entries
        )
        return f"{keys} {self.what or entries[0].title}"


#: a key legend: rows of entries
Legend = tuple[tuple[LegendEntry, ...], ...]


def legend_text(rows: Legend) -> str:
    """A key legend as shown: each row's entries two spaces apart, one row a line."""
    return "\n".join("  ".join(entry.text() for entry in row) for row in rows)


#: the legend beside the maze editor's maze
EDITOR_LEGEND: Legend = (
    (
        LegendEntry(("editor.up", "editor.down", "editor.left", "editor.right"), "arrows", "move"),
        LegendEntry(("editor.wall",), "space/click"),
    ),
    (
        LegendEntry(("editor.start",), what="start (again: turn)"),
        LegendEntry(("editor.exit",)),
    ),
    (
        LegendEntry(("editor.undo",)),
        LegendEntry(("editor.redo",)),
        LegendEntry(("editor.next_problem",), what="problem"),
    ),
    (
        LegendEntry(("editor.new",)),
        LegendEntry(("editor.generate",)),
        LegendEntry(("editor.unicode",)),
    ),
    (
        LegendEntry(("editor.save",)),
        LegendEntry(("editor.save_as",)),
        LegendEntry(("editor.leave",)),
    ),
)
#: the legend beside the replay's maze
REPLAY_LEGEND: Legend = (
    (
        LegendEntry(("replay.back", "replay.step"), what="step"),
        LegendEntry(("replay.back10", "replay.step10"), what="10"),
    ),
    (
        LegendEntry(("replay.play",)),
        LegendEntry(("replay.faster", "replay.slower"), what="speed"),
    ),
    (
        LegendEntry(("replay.first", "replay.last"), what="first/last"),
        LegendEntry(("replay.leave",)),
    ),
    (
        LegendEntry(("replay.picture",), what="picture"),
        LegendEntry(("replay.plot",), what="plot"),
    ),
)
