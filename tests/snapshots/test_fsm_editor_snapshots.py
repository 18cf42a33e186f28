"""SVG snapshots of the FSM editor: the text with its check at 80x24, the diagram in the
text's place (ctrl+t) at 80x24, and both side by side at 120x40. Nothing runs on a clock:
each picture is taken once the text's check is done."""

from __future__ import annotations

from pathlib import Path

import pytest
from textual.pilot import Pilot
from textual.widgets import TextArea

from tests.snapshots.test_editor_snapshots import Host
from tests.waiting import until
from workbench.control.station import LabStation
from workbench.files.workspace import FileAccess
from workbench.sim.mazeio import load_maze
from workbench.tui.screens.fsm_editor import FsmEditorScreen

ROOT = Path(__file__).resolve().parents[2]
RIGHT_WALL = str(ROOT / "workbench" / "fsm" / "algorithms" / "right-wall.yaml")
BAD = "initial: Ahead\nstates:\n  Ahead:\n    on_enter: [{move: 1}]\n    transitions:\n" \
      "      - {when: frnt < 50, to: Ahead}\n"  # fmt: skip


def editor_on(path: str, unicode: bool = False, files: FileAccess | None = None) -> Host:
    maze = load_maze(ROOT / "mazes" / "erobotic.txt")
    more = {"files": files} if files is not None else {}
    station = LabStation.open(maze, "erobotic", noise="off", **more)
    return Host(FsmEditorScreen(station, path, unicode=unicode))


def checked_then(*keys: str):
    async def run_before(pilot: Pilot) -> None:
        await pilot.pause()
        screen = pilot.app.screen
        assert isinstance(screen, FsmEditorScreen)
        await until(lambda: screen.checked_text == screen.text, "the text checked")
        screen.query_one(TextArea).cursor_blink = False
        screen.set_focus(None)  # no text cursor (blinking or not) in the picture
        await pilot.press(*keys)
        await pilot.pause()

    return run_before


def test_fsm_editor_with_a_problem_80x24(snap_compare, tmp_path):
    files = FileAccess.confined_to(tmp_path / "ann")
    (tmp_path / "ann" / "mine.yaml").write_text(BAD)
    app = editor_on("~/mine.yaml", files=files)
    assert snap_compare(app, run_before=checked_then(), terminal_size=(80, 24))


@pytest.mark.parametrize("unicode", [False, True], ids=["ascii", "unicode"])
def test_fsm_diagram_80x24(snap_compare, unicode):
    app = editor_on(RIGHT_WALL, unicode)
    assert snap_compare(app, run_before=checked_then("ctrl+t"), terminal_size=(80, 24))


def test_fsm_editor_and_diagram_side_by_side_120x40(snap_compare):
    app = editor_on(RIGHT_WALL, unicode=True)
    assert snap_compare(app, run_before=checked_then(), terminal_size=(120, 40))
