"""The maze editor screen: draw walls, place the start and exits, check and save the maze.

All editing happens in :class:`~workbench.sim.editing.MazeEditor`; this screen draws it and
routes keys and clicks to it. On leaving, a changed maze that is valid goes to the station, so
the robot runs on it; the screen is dismissed with that maze (or None when the station kept its
maze).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import ClassVar

from rich.text import Text
from textual import on
from textual.app import ComposeResult
from textual.binding import BindingType
from textual.containers import Horizontal, Vertical
from textual.screen import Screen
from textual.widgets import OptionList, Static
from textual.widgets.option_list import Option

from workbench.control.station import LabStation
from workbench.sim.editing import EditorError, Finding, GenerateOptions, MazeEditor
from workbench.sim.maze import Maze

from ..dialogs.generate import GenerateDialog
from ..dialogs.path import PathDialog
from ..dialogs.size import SizeDialog
from ..dialogs.unsaved import Choice, UnsavedDialog
from ..host import FollowsUnicode, MazeChanged, Say, ToggleUnicode
from ..keys import EDITOR_KEY_IDS, EDITOR_LEGEND, bindings, legend_text
from ..widgets.key_bar import KeyBar
from ..widgets.maze_view import MazeView

SAVE_HELP = (
    "The file is written atomically: a crash leaves the old file or the new one, never half. "
    "A .maz name writes a micromouse binary maze; any other name the workbench text format."
)


def _problem_line(finding: Finding) -> str:
    if finding.cell is None:
        return finding.message
    return f"({finding.cell[0]}, {finding.cell[1]}) {finding.message}"


class EditorScreen(FollowsUnicode, Screen[Maze | None]):
    """Edit the station's maze; dismissed with the maze the robot now runs on, or None."""

    AUTO_FOCUS = ""

    DEFAULT_CSS = """
    EditorScreen #editor-title {
        height: 1;
        padding: 0 1;
        background: $boost;
        text-style: bold;
    }
    EditorScreen #editor-body {
        height: 1fr;
    }
    EditorScreen #editor-maze {
        width: 1fr;
        height: 1fr;
    }
    EditorScreen #editor-side {
        width: 34;
        height: 1fr;
        padding: 0 1;
        border-left: vkey $panel;
    }
    EditorScreen #editor-info {
        height: auto;
    }
    EditorScreen #editor-problems-title {
        height: 1;
        margin-top: 1;
        text-style: bold;
    }
    EditorScreen #editor-problems-title.-ok {
        color: $text-success;
    }
    EditorScreen #editor-problems-title.-bad {
        color: $text-error;
    }
    EditorScreen #editor-problems {
        height: 1fr;
        min-height: 3;
        border: none;
        padding: 0;
        background: $surface;
    }
    EditorScreen #editor-problems:focus {
        background-tint: $foreground 5%;
    }
    EditorScreen #editor-status {
        height: auto;
        max-height: 4;
        color: $text-muted;
    }
    EditorScreen #editor-status.-error {
        color: $text-error;
    }
    EditorScreen #editor-keys {
        height: auto;
        margin-top: 1;
        color: $text-muted;
    }
    """

    BINDINGS: ClassVar[list[BindingType]] = [*bindings(*EDITOR_KEY_IDS)]

    def __init__(
        self,
        station: LabStation,
        path: str | None = None,
        unicode: bool = False,
        *,
        name: str | None = None,
        id: str | None = None,
        classes: str | None = None,
    ) -> None:
        super().__init__(name=name, id=id, classes=classes)
        self.station = station
        self.editor = MazeEditor(station.maze, path, station.files)
        self._unicode = unicode
        self._generate_options = GenerateOptions()
        self._shown_problems: tuple[bool, tuple[str, ...]] | None = None
        self._problem_index = -1
        #: the last message shown under the problems (what an action did, or why it failed)
        self.status = ""

    # -- layout ----------------------------------------------------------------------------
    def compose(self) -> ComposeResult:
        yield Static(id="editor-title", markup=False)
        with Horizontal(id="editor-body"):
            yield MazeView(
                self.editor.maze,
                unicode=self._unicode,
                trail=False,
                follow=False,
                id="editor-maze",
            )
            with Vertical(id="editor-side"):
                yield Static(id="editor-info", markup=False)
                yield Static(id="editor-problems-title", markup=False)
                yield OptionList(id="editor-problems", markup=False)
                yield Static(id="editor-status", markup=False)
                yield Static(legend_text(EDITOR_LEGEND), id="editor-keys", markup=False)
        yield KeyBar()

    def on_mount(self) -> None:
        self._refresh()

    # -- public ------------------------------------------------------------------------------
    @property
    def unicode(self) -> bool:
        return self._unicode

    @property
    def dirty(self) -> bool:
        """True while the maze has changes that are not saved."""
        return self.editor.dirty

    def set_unicode(self, unicode: bool) -> None:
        self._unicode = unicode
        if self.is_mounted:
            self.query_one(MazeView).set_unicode(unicode)

    # -- drawing -------------------------------------------------------------------------------
    def _refresh(self) -> None:
        editor = self.editor
        view = self.query_one(MazeView)
        if view.maze is not editor.maze:
            view.set_maze(editor.maze)
        view.set_cursor(editor.cursor)
        marker = " (modified)" if editor.dirty else ""
        where = editor.files.shown(editor.path) if editor.path else "not saved yet"
        self.query_one("#editor-title", Static).update(
            f"Maze editor: {editor.title()}{marker}  [{where}]"
        )
        self.query_one("#editor-info", Static).update(self._info())
        self._show_problems(editor.problems)

    def _info(self) -> Text:
        maze = self.editor.maze
        x, y = self.editor.cursor
        if maze.start == (x, y):
            kind = f"start facing {maze.heading}"
        elif maze.is_exit(x, y):
            kind = "exit"
        else:
            kind = "wall" if maze.is_wall(x, y) else "floor"
        text = Text()
        text.append(f"Cursor ({x}, {y}): ", style="bold")
        text.append(f"{kind}\n")
        start = f"({maze.start[0]}, {maze.start[1]}) {maze.heading}" if maze.start else "none"
        text.append(f"Start {start}\n")
        exits = len(maze.exits)
        text.append(f"{maze.width} x {maze.height} blocks, {exits} exit{'s' * (exits != 1)}")
        return text

    def _show_problems(self, findings: list[Finding]) -> None:
        title = self.query_one("#editor-problems-title", Static)
        title.set_class(not findings, "-ok")
        title.set_class(bool(findings), "-bad")
        if findings:
            title.update(f"Problems ({len(findings)}): p or click")
            lines = tuple(_problem_line(f) for f in findings)
        else:
            title.update("No problems: ready to run")
            lines = tuple(f"note: {n}" for n in self.editor.notes())
        shown = (bool(findings), lines)
        if shown == self._shown_problems:
            return
        self._shown_problems = shown
        self._problem_index = -1
        options = [Option(line, disabled=not findings) for line in lines]
        self.query_one("#editor-problems", OptionList).set_options(options)

    def _status(self, text: str, error: bool = False) -> None:
        self.status = text
        status = self.query_one("#editor-status", Static)
        status.update(text)
        status.set_class(error, "-error")

    # -- editing -----------------------------------------------------------------------------
    def action_move(self, dx: int, dy: int) -> None:
        self.editor.move(dx, dy)
        self._refresh()

    def action_toggle_wall(self) -> None:
        self._toggle(None)

    def _toggle(self, cell: tuple[int, int] | None) -> None:
        try:
            self.editor.toggle_wall(cell)
        except EditorError as exc:
            self._status(str(exc), error=True)
        else:
            self._status_block()
        self._refresh()

    def _status_block(self) -> None:
        x, y = self.editor.cursor
        kind = "wall" if self.editor.maze.is_wall(x, y) else "floor"
        self._status(f"({x}, {y}) is {kind} now")

    @on(MazeView.BlockClicked)
    def _block_clicked(self, event: MazeView.BlockClicked) -> None:
        event.stop()
        self._toggle(event.cell)

    def action_start(self) -> None:
        heading = self.editor.set_start()
        x, y = self.editor.cursor
        self._status(f"start at ({x}, {y}) facing {heading}; s again turns it")
        self._refresh()

    def action_exit(self) -> None:
        present = self.editor.toggle_exit()
        x, y = self.editor.cursor
        self._status(f"exit {'added at' if present else 'removed from'} ({x}, {y})")
        self._refresh()

    def action_undo(self) -> None:
        self._status("undone" if self.editor.undo() else "nothing to undo")
        self._refresh()

    def action_redo(self) -> None:
        self._status("redone" if self.editor.redo() else "nothing to redo")
        self._refresh()

    def action_new(self) -> None:
        maze = self.editor.maze
        self.app.push_screen(SizeDialog(maze.width, maze.height), self._new_size)

    def _new_size(self, size: tuple[int, int] | None) -> None:
        if size is None:
            return
        self.editor.new(*size)
        self._status(f"new {size[0]} x {size[1]} maze; ctrl+z brings the old one back")
        self._refresh()

    def action_generate(self) -> None:
        self.app.push_screen(GenerateDialog(self._generate_options), self._generated)

    def _generated(self, options: GenerateOptions | None) -> None:
        if options is None:
            return
        self._generate_options = options
        o = options
        try:
            self.editor.generate(o.width, o.height, o.seed, o.style, o.exit)
        except EditorError as exc:
            self._status(str(exc), error=True)
            return
        self._status(f"generated {self.editor.maze.name}; ctrl+z brings the old one back")
        self._refresh()

    # -- problems ----------------------------------------------------------------------------
    @on(OptionList.OptionSelected, "#editor-problems")
    def _problem_selected(self, event: OptionList.OptionSelected) -> None:
        event.stop()
        self._go_to_problem(event.option_index)
        self.set_focus(None)

    def action_next_problem(self) -> None:
        findings = self.editor.problems
        if not findings:
            self._status("no problems")
            return
        self._go_to_problem((self._problem_index + 1) % len(findings))

    def _go_to_problem(self, index: int) -> None:
        findings = self.editor.problems
        if not 0 <= index < len(findings):
            return
        self._problem_index = index
        finding = findings[index]
        self.query_one("#editor-problems", OptionList).highlighted = index
        if finding.cell is None:
            self._status(f"{finding.message}: {finding.hint}")
        else:
            self.editor.move_to(finding.cell)
            self._status(f"({finding.cell[0]}, {finding.cell[1]}): {finding.hint}")
        self._refresh()

    # -- saving ------------------------------------------------------------------------------
    def _save(self, path: str | None) -> bool:
        try:
            written = self.editor.save(path)
        except EditorError as exc:
            self._status(str(exc), error=True)
            return False
        count = len(self.editor.problems)
        extra = f" (with {count} problem{'s' * (count != 1)} still to fix)" if count else ""
        self._status(f"saved to {self.editor.files.shown(written)}{extra}")
        self._refresh()
        return True

    def action_save(self) -> None:
        if self.editor.path is None:
            self._ask_path(None)
        else:
            self._save(None)

    def action_save_as(self) -> None:
        self._ask_path(None)

    def _ask_path(
        self, after: Callable[[], object] | None, value: str | None = None, error: str = ""
    ) -> None:
        """Ask where to save; on success run ``after``, on failure ask again with the reason."""

        def chosen(path: str | None) -> None:
            if path is None:
                return
            if self._save(path):
                if after is not None:
                    after()
            else:
                self._ask_path(after, path, self.status)

        dialog = PathDialog(
            "Save maze as",
            SAVE_HELP,
            value=self.editor.suggested_path() if value is None else value,
            note=self.station.files.note(),
            action="Save",
            error=error,
        )
        self.app.push_screen(dialog, chosen)

    # -- leaving -----------------------------------------------------------------------------
    def ask_before(self, action: Callable[[], object]) -> None:
        """Run ``action`` (quit, switch...) once the changes are saved or discarded.

        Without unsaved changes it runs at once; otherwise the save / discard / cancel prompt
        comes first, and cancel (or a save that is abandoned) does not run it.
        """
        if self.editor.dirty:
            self._prompt(lambda _discarded: action())
        else:
            action()

    def _prompt(self, then: Callable[[bool], object]) -> None:
        """The unsaved-changes prompt; ``then(discarded)`` after a save or a discard."""

        def chosen(choice: Choice | None) -> None:
            if choice == "save":
                if self.editor.path is None:
                    self._ask_path(lambda: then(False))
                elif self._save(None):
                    then(False)
            elif choice == "discard":
                then(True)

        self.app.push_screen(UnsavedDialog(self.editor.title()), chosen)

    def action_leave(self) -> None:
        problems = self.query_one("#editor-problems", OptionList)
        if problems.has_focus:
            self.set_focus(None)
            return
        if self.editor.dirty:
            self._prompt(lambda discarded: self._leave(discard=discarded))
        else:
            self._leave(discard=False)

    def _leave(self, discard: bool) -> None:
        editor = self.editor
        kept = editor.saved if discard else editor.maze
        maze, note = editor.handover(discard)
        if maze is not None:
            self.station.put_edited_maze(
                maze, editor.opened, hand_blocks=editor.hand_blocks(discard)
            )
        on_robot = maze is not None or kept == editor.opened
        if editor.path is not None and kept == editor.saved and on_robot:
            # the maze the robot is on is this file: the editor opens it there next time
            self.post_message(MazeChanged(editor.path))
        if maze is not None:
            self.post_message(Say(f"the robot is on the edited maze {maze.name}"))
        elif note:
            self.post_message(Say(note))
        if len(self.app.screen_stack) > 1 and self.app.screen is self:
            self.dismiss(maze)
        else:
            self.app.exit(maze)

    def action_unicode(self) -> None:
        self.post_message(ToggleUnicode())
