"""ASCII mode is plain ASCII on every screen and in every dialog, at 80x24.

A terminal or a font without Unicode box drawing (an old SSH client, a serial console) shows
the workbench in ASCII mode; one stray emoji, block character or rounded corner there is a box
of question marks. The walk opens each screen and dialog with data in it (a finished run with
a record, a running algorithm, a lab exercise with objectives and questions, a maze file with
many problems) and reads back every cell the terminal would show.
"""

from __future__ import annotations

from pathlib import Path

import pytest
from textual.pilot import Pilot
from textual.widgets import Input

from workbench.files.bundled import MAZE_DIR
from workbench.labs.signoff.instructors import KdfParams, create_instructor
from workbench.tui.app import make_app
from workbench.tui.screens.replay import ReplayScreen
from workbench.tui.screens.runs import RunsScreen
from workbench.wire.settings import AppSettings

from .labs_support import open_exercise
from .support import run, screen_lines

FAST = KdfParams(n=2**10, r=8, p=1)  # cheap scrypt for tests only
BAD_MAZE = "---\nname: broken\n---\n" + "\n".join("#.?x" * 5 for _ in range(40)) + "\n"


def not_ascii(lines: list[str]) -> list[str]:
    return [f"{n:2}: {line}" for n, line in enumerate(lines) if not line.isascii()]


class Walk:
    def __init__(self, pilot: Pilot) -> None:
        self.pilot = pilot
        self.seen: dict[str, list[str]] = {}

    async def look(self, name: str) -> None:
        await self.pilot.pause()
        await self.pilot.pause()
        self.seen[name] = not_ascii(screen_lines(self.pilot.app))

    async def press(self, *keys: str) -> None:
        await self.pilot.press(*keys)
        await self.pilot.pause()


@pytest.mark.long
def test_every_screen_and_dialog_is_plain_ascii_in_ascii_mode(tmp_path: Path):
    data = tmp_path / "data"
    create_instructor(data, "Dr Chen", "correct horse battery", kdf=FAST)
    bad = tmp_path / "bad.txt"
    bad.write_text(BAD_MAZE)
    app = make_app(
        AppSettings(
            MAZE_DIR / "rank-wall-wins.txt",
            paused=True,
            noise="off",
            student="ana",
            partner="ben",
            data_dir=data,
            record_dir=str(tmp_path / "runs"),
        ),
    )
    assert not app.unicode

    async def body(pilot: Pilot) -> None:
        w = Walk(pilot)
        station = app.station
        await w.look("main screen")
        station.select_algorithm("right-wall")
        station.apply_algorithm_preset()
        station.start()
        station.step(60 * 30)
        assert [run.ended for run in station.runs] == ["exit"]
        await w.look("main screen, a run finished")
        station.start()
        station.step(60 * 12)
        await w.look("main screen, an algorithm running")
        await w.press("g")
        await w.look("algorithm dialog")
        await w.press("escape", "o")
        await w.look("sensor ports dialog")
        await w.press("escape", "m")
        await w.look("maze dialog")
        pilot.app.screen.query_one("#path", Input).value = str(bad)
        await w.press("enter")
        await w.look("maze dialog with many problems")
        await w.press("escape", "question_mark")
        await w.look("help")
        await w.press("escape", "ctrl+p")
        await w.look("command palette")
        await w.press("escape", "R")
        assert isinstance(app.screen, RunsScreen)
        await w.look("runs screen")
        await w.press("enter")
        assert isinstance(app.screen, ReplayScreen)
        await w.look("replay screen")
        await w.press("escape", "escape", "e")
        await w.look("maze editor")
        await w.press("g")
        await w.look("generate dialog")
        await w.press("escape", "escape")
        screen = await open_exercise(pilot, "unity-simulator/wall-following")
        await w.look("labs screen")
        screen.query_one("#labs-scroll").scroll_end(animate=False)
        await w.look("labs screen, scrolled to the questions")
        await w.press("i")
        await w.look("sign-off dialog")
        await w.press("escape", "escape")
        await pilot.resize_terminal(60, 20)
        await w.look("terminal too small")
        await pilot.resize_terminal(80, 24)
        found = {name: lines for name, lines in w.seen.items() if lines}
        assert found == {}, "\n".join(f"{k}:\n" + "\n".join(v) for k, v in found.items())
        assert len(w.seen) == 17

    run(app, body)


def test_the_names_dialog_at_start_is_plain_ascii(tmp_path: Path):
    app = make_app(
        AppSettings(paused=True, student="ana", data_dir=tmp_path / "data", ask_names=True)
    )

    async def body(pilot: Pilot) -> None:
        await pilot.pause()
        assert not_ascii(screen_lines(app)) == []

    run(app, body)
