"""SVG snapshots of the maze view at 80x24, ASCII and Unicode, with a robot stepped a fixed run."""

from __future__ import annotations

from textual.app import App, ComposeResult

from workbench.fsm.algorithms import load_algorithm
from workbench.fsm.machine import FsmController, bind_sensors, preset_sensors
from workbench.sim.generate import generate
from workbench.sim.session import Session
from workbench.tui.widgets import MazeView

SIZE = (80, 24)


class MazeViewHost(App):
    """The maze view alone, showing a right-wall run stepped a fixed number of steps."""

    def __init__(self, unicode: bool, steps: int, cursor: tuple[int, int] | None = None) -> None:
        super().__init__()
        self.maze = generate(16, 16, 7)
        self.unicode = unicode
        self.steps = steps
        self.cursor = cursor

    def compose(self) -> ComposeResult:
        yield MazeView(self.maze, unicode=self.unicode)

    def on_mount(self) -> None:
        definition = load_algorithm("right-wall")
        sensors = preset_sensors(definition, "unity")
        session = Session(self.maze, "unity", sensors, noise="off")
        session.attach(
            FsmController(definition, {}, "unity"),
            bind_sensors(definition, sensors, "unity"),
            "algorithm",
        )
        view = self.query_one(MazeView)
        for _ in range(self.steps // 3):
            for _ in range(3):
                session.step()
            view.show(session.snapshot(), session.world.cell)
        if self.cursor is not None:
            view.set_cursor(self.cursor)


def test_maze_view_ascii(snap_compare):
    assert snap_compare(MazeViewHost(unicode=False, steps=1500), terminal_size=SIZE)


def test_maze_view_unicode(snap_compare):
    assert snap_compare(MazeViewHost(unicode=True, steps=1500), terminal_size=SIZE)


def test_maze_view_editor_cursor(snap_compare):
    app = MazeViewHost(unicode=False, steps=0, cursor=(5, 29))
    assert snap_compare(app, terminal_size=SIZE)
