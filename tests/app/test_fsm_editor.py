"""The FSM editor at 80x24: a student writes a right-wall machine from an empty file, through
the forms and by typing, sees a problem appear at its line and go, saves it in the
workspace (undo kept), runs it to the exit and watches the diagram light the state it is in."""

from __future__ import annotations

import threading
from pathlib import Path

from rich.text import Text
from textual.pilot import Pilot
from textual.widgets import Input, Static, TextArea

from tests.waiting import DEADLINE, until
from workbench.files.workspace import workspace_folder
from workbench.fsm.editing import check
from workbench.tui.app import make_app
from workbench.tui.dialogs.algorithm import AlgorithmModal
from workbench.tui.dialogs.fsm_form import STATE, TRANSITION, FormDialog
from workbench.tui.dialogs.path import PathDialog
from workbench.tui.screens import fsm_editor
from workbench.tui.screens.fsm_editor import FsmEditorScreen
from workbench.wire.settings import AppSettings

from .support import run

ROOT = Path(__file__).resolve().parents[2]
EROBOTIC = ROOT / "mazes" / "erobotic.txt"
STATES = [
    ("Ahead", "move: 1"),
    ("Beside", "move: 1; timer: 0.5"),
    ("Right", "turn: 90"),
    ("Settle", "move: 1; timer: 1.5"),
    ("Left", "turn: -90"),
]
TRANSITIONS = [
    ("Ahead", "Beside", "right > 100"),
    ("Ahead", "Left", "front < 50"),
    ("Beside", "Right", "timer_done or front < 50"),
    ("Right", "Settle", "turn_done"),
    ("Settle", "Left", "front < 50"),
    ("Settle", "Ahead", "timer_done or right <= 100"),
]
#: the one transition the first test types by hand
LAST = ("Left", "Ahead", "turn_done")


def served(tmp_path: Path):
    workspace = workspace_folder(tmp_path / "data", "ann")
    app = make_app(AppSettings(maze_path=EROBOTIC, workspace=workspace))
    return app, workspace


def problems(editor: FsmEditorScreen) -> str:
    return str(editor.query_one("#fsm-problems", Static).render())


async def checked(pilot: Pilot, editor: FsmEditorScreen) -> None:
    """Wait for the check of the text as it stands."""
    await until(lambda: editor.checked_text == editor.text, "the text checked")
    await pilot.pause()


async def fill(pilot: Pilot, values: dict[str, str]) -> None:
    for field_id, value in values.items():
        pilot.app.screen.query_one(f"#{field_id}", Input).value = value
    await pilot.press("enter")
    await pilot.pause()


async def type_text(pilot: Pilot, text: str) -> None:
    await pilot.press(*["space" if c == " " else c for c in text])


async def write_right_wall(pilot: Pilot, editor: FsmEditorScreen, whole: bool = False) -> None:
    """The right-wall machine through the forms (``whole``: with :data:`LAST` too)."""
    for name, actions in STATES:
        await pilot.press("ctrl+n")
        assert isinstance(pilot.app.screen, FormDialog) and pilot.app.screen.form is STATE
        await fill(pilot, {"state-name": name, "state-actions": actions})
        assert pilot.app.screen is editor, editor.status
        if name == STATES[0][0]:  # one state alone is a machine already, and said as one
            await checked(pilot, editor)
            assert problems(editor).startswith("No problems: 1 state. "), problems(editor)
    for source, target, when in [*TRANSITIONS, *([LAST] if whole else [])]:
        await pilot.press("ctrl+b")
        assert isinstance(pilot.app.screen, FormDialog)
        assert pilot.app.screen.form is TRANSITION
        await fill(pilot, {"tr-from": source, "tr-to": target, "tr-when": when})
        assert pilot.app.screen is editor, editor.status


def test_write_save_and_run_a_right_wall_machine(tmp_path):
    app, workspace = served(tmp_path)

    async def body(pilot: Pilot) -> None:
        await pilot.press("F")
        editor = app.screen
        assert isinstance(editor, FsmEditorScreen)
        await checked(pilot, editor)
        assert "states" in problems(editor)  # a new file has none yet
        await pilot.press("ctrl+b")  # a transition before its states: refused, saying why
        await fill(pilot, {"tr-from": "Ahead", "tr-to": "Left"})
        form = app.screen
        assert isinstance(form, FormDialog)
        assert "no state 'Ahead' yet: add it first" in str(form.query_one("#error").render())
        await pilot.press("escape")
        assert app.screen is editor
        await write_right_wall(pilot, editor)

        # the last transition typed by hand, with a slip first
        area = editor.query_one(TextArea)
        lines = area.text.split("\n")
        row = max(i for i, line in enumerate(lines) if line.strip() == "transitions: []")
        area.cursor_location = (row, len(lines[row]))
        await pilot.press("backspace", "backspace", "enter")
        await type_text(pilot, "      - {when: turn_done, to: Ahed}")
        await checked(pilot, editor)
        assert f"{row + 2}:" in problems(editor) and "'Ahed'" in problems(editor)
        assert "did you mean 'Ahead'" in problems(editor)
        await pilot.press("backspace", "backspace", "a", "d", "}")
        await checked(pilot, editor)
        assert problems(editor).startswith("No problems: 5 states")

        # save: a new file asks for its name; undo is kept after the save
        await pilot.press("ctrl+s")
        assert isinstance(app.screen, PathDialog)
        app.screen.query_one("#path", Input).value = "~/right-wall-mine.yaml"
        await pilot.press("enter")
        await pilot.pause()
        saved = workspace / "right-wall-mine.yaml"
        assert saved.read_text() == area.text and not editor.dirty
        await pilot.press("ctrl+z")
        assert area.text != saved.read_text() and editor.dirty
        await pilot.press("ctrl+y")
        assert area.text == saved.read_text()

        # run it on the station at once and watch the diagram follow it
        await pilot.press("ctrl+r")
        station = app.station
        assert station.driving is not None, editor.status
        assert station.algorithm is not None and station.algorithm.source == str(saved)
        station.set_speed(10.0)  # each state lasts a few ticks of the screen
        seen: list[str] = []

        def follow() -> bool:
            state = editor.lit[0]
            if state is not None and (not seen or seen[-1] != state):
                seen.append(state)
            return bool(station.runs) and station.runs[-1].ended == "exit"

        await until(follow, "the machine's run reached the exit", timeout=60)
        assert {"Ahead", "Left", "Right", "Settle"} <= set(seen)
        assert station.runs[-1].program_name == "right-wall-mine.yaml"

    run(app, body)


def test_the_diagram_lights_the_current_state_and_the_last_transition(tmp_path):
    app, workspace = served(tmp_path)

    def lit_lines(editor: FsmEditorScreen) -> set[str]:
        content = editor.query_one("#fsm-diagram", Static).content
        assert isinstance(content, Text)
        lines = content.plain.split("\n")
        starts = [0]
        for line in lines:
            starts.append(starts[-1] + len(line) + 1)
        return {
            lines[i]
            for span in content.spans
            for i in range(len(lines))
            if span.start <= starts[i] < span.end
        }

    async def body(pilot: Pilot) -> None:
        await pilot.press("F")
        editor = app.screen
        assert isinstance(editor, FsmEditorScreen)
        await write_right_wall(pilot, editor)
        await pilot.press("ctrl+s")
        app.screen.query_one("#path", Input).value = "mine.yaml"
        await pilot.press("enter")
        await pilot.pause()
        assert (workspace / "mine.yaml").exists()
        station = app.station
        await pilot.press("ctrl+r")
        station.pause()  # the run goes on by steps from here
        await pilot.press("ctrl+t")  # 80 columns: the diagram in the text's place
        assert not editor.query_one(TextArea).display
        assert editor.query_one("#fsm-diagram-box").display
        app.refresh_views()
        before = await until(lambda: editor.lit[0], "a state lit")
        assert any(line.startswith("| " + before) for line in lit_lines(editor))
        while editor.lit[0] == before:
            station.step(station.session.every)
            app.refresh_views()
            await pilot.pause()
        state, arrow = editor.lit
        assert state is not None and arrow is not None and arrow[0] == before
        lit = lit_lines(editor)
        assert any(line.startswith("| " + state) for line in lit), lit
        assert not any(line.startswith("| " + before) for line in lit), lit
        assert any(f"-> {state}" in line for line in lit), lit
        await pilot.press("ctrl+t")
        assert editor.query_one(TextArea).display

    run(app, body)


def test_the_algorithm_dialog_opens_the_chosen_file_in_the_editor(tmp_path):
    app, workspace = served(tmp_path)
    (workspace / "mine.yaml").write_text("initial: A\nstates:\n  A: {}\n")

    async def body(pilot: Pilot) -> None:
        await pilot.press("g")
        assert isinstance(app.screen, AlgorithmModal)
        app.screen.query_one("#alg-path", Input).value = "mine.yaml"
        await pilot.click("#alg-edit")
        editor = await until(lambda: isinstance(app.screen, FsmEditorScreen) and app.screen)
        assert isinstance(editor, FsmEditorScreen)
        assert editor.text == "initial: A\nstates:\n  A: {}\n"
        assert editor.draft.shown == "~/mine.yaml"

    run(app, body)


def test_a_hostile_file_never_holds_the_editor(tmp_path, monkeypatch):
    """The check runs beside the screen: keys are answered while it works; a file past the
    limits is one problem and is not saved; a machine of thousands of states is drawn in
    part."""
    app, workspace = served(tmp_path)
    n = 3000
    big = "initial: S0\nstates:\n" + "".join(
        f"  S{i}:\n    transitions: [{{to: S{(i + 1) % n}, when: timer_done}}]\n" for i in range(n)
    )
    (workspace / "big.yaml").write_text(big)
    release = threading.Event()
    started = threading.Event()

    def slow_check(text: str, filename: str):
        started.set()
        release.wait(DEADLINE)
        return check(text, filename)

    monkeypatch.setattr(fsm_editor, "check", slow_check)

    async def body(pilot: Pilot) -> None:
        await pilot.press("g")
        app.screen.query_one("#alg-path", Input).value = "big.yaml"
        await pilot.click("#alg-edit")
        editor = await until(lambda: isinstance(app.screen, FsmEditorScreen) and app.screen)
        assert isinstance(editor, FsmEditorScreen)
        await until(started.is_set, "the check under way")
        await pilot.press("ctrl+t")  # answered while the check works
        assert editor.has_class("-diagram") and editor.checked is None
        release.set()
        await checked(pilot, editor)
        assert problems(editor).startswith(f"No problems: {n} states")
        assert editor.diagram is not None
        assert editor.diagram.lines[-1] == f"... and {n - 200} more states, not drawn"

        area = editor.query_one(TextArea)
        deep = "(" * 60 + "1" + ")" * 60
        area.load_text(f"initial: A\nstates:\n  A:\n    transitions: [{{to: A, when: '{deep}'}}]\n")
        await checked(pilot, editor)
        assert "nest more than 50 deep" in problems(editor)
        area.load_text(("# " + "x" * 4093 + "\n") * 260)  # over 1 MiB in few, cheap lines
        await checked(pilot, editor)
        assert "over the 1,048,576 bytes an FSM file may hold" in problems(editor)
        await pilot.press("ctrl+s")
        assert "not saved" in editor.status
        assert (workspace / "big.yaml").read_text() == big

    run(app, body)


def test_leaving_a_new_machine_with_changes_asks_about_this_new_fsm(tmp_path):
    from workbench.tui.dialogs.unsaved import UnsavedDialog

    app, _ = served(tmp_path)

    async def body(pilot: Pilot) -> None:
        await pilot.press("F")
        editor = app.screen
        assert isinstance(editor, FsmEditorScreen)
        await pilot.press("ctrl+n")
        await fill(pilot, {"state-name": "Forward", "state-actions": "move: 1"})
        await pilot.press("escape")
        await until(lambda: isinstance(app.screen, UnsavedDialog), "the unsaved question")
        said = " ".join(str(s.render()) for s in app.screen.query(Static))
        assert "This new FSM has changes that are not saved." in said, said
        await pilot.press("d")
        await until(lambda: app.screen is not editor and not isinstance(app.screen, UnsavedDialog))

    run(app, body)
