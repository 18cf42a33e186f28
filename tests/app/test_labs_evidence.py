"""At 80x24, through the keys: a sensors objective needs a run with the sensors, Generate in
the editor is not editing the maze, a capped question stops taking answers and waits for the
instructor, and the sign-off says so."""

from __future__ import annotations

from dataclasses import replace

from textual.pilot import Pilot
from textual.widgets import Input

from workbench.labs.model import load_labs
from workbench.labs.signoff.instructors import KdfParams, create_instructor
from workbench.tui.dialogs.generate import GenerateDialog
from workbench.tui.dialogs.path import PathDialog
from workbench.tui.dialogs.signoff import SignoffModal
from workbench.tui.screens import labs as labs_screen
from workbench.tui.screens.editor import EditorScreen
from workbench.tui.screens.main import MainScreen

from .labs_support import DRIVE, lab_app, objective_lines, open_exercise, text
from .support import run

FAST = KdfParams(n=2**10, r=8, p=1)  # cheap scrypt for tests only


def test_the_set_up_alone_does_not_pass_a_sensors_objective(tmp_path):
    app = lab_app(tmp_path / "data")

    async def body(pilot: Pilot) -> None:
        screen = await open_exercise(pilot, "web-simulator/wall-main")
        await pilot.press("a")
        await pilot.pause()
        assert objective_lines(screen)[0] == (
            "[ ] distance 1 right and touch 2 front: the robot carries them: now drive it "
            "(keys, x or VIPLE) for a run"
        )
        await pilot.press("escape", "w")
        app.station.step(20)
        await pilot.press("space", "l")
        await pilot.pause()
        assert objective_lines(screen)[0] == (
            "[X] distance 1 right and touch 2 front: run 1 (keys) carried distance:1:right, "
            "touch:2:front"
        )

    run(app, body)


async def leave_the_editor_saving(pilot: Pilot, path) -> None:
    """Escape, save at the prompt, and (a generated maze has no file yet) the path."""
    await pilot.press("escape", "s")
    await pilot.pause()
    dialog = pilot.app.screen
    if isinstance(dialog, PathDialog):
        dialog.query_one("#path", Input).value = str(path)
        await pilot.press("enter")
        await pilot.pause()
    assert isinstance(pilot.app.screen, MainScreen)


def test_a_generated_maze_is_not_an_edit_until_a_block_is_changed_by_hand(tmp_path):
    app = lab_app(tmp_path / "data")

    async def body(pilot: Pilot) -> None:
        screen = await open_exercise(pilot, DRIVE)
        await pilot.press("a", "escape", "e")
        await pilot.pause()
        assert isinstance(app.screen, EditorScreen)
        await pilot.press("g")
        assert isinstance(app.screen, GenerateDialog)
        await pilot.click("#ok")
        await pilot.pause()
        await leave_the_editor_saving(pilot, tmp_path / "generated.txt")
        await pilot.press("l")
        await pilot.pause()
        assert objective_lines(screen)[1] == (
            "[ ] edited the maze and kept it valid: edit 1 added or removed no block by hand "
            "(Generate, New and loading do not count): in the editor (e) put or take away a "
            "block yourself"
        )
        await pilot.press("escape", "e")
        await pilot.pause()
        editor = app.screen
        assert isinstance(editor, EditorScreen)
        maze = app.station.maze
        target = next((x, y) for y in range(1, maze.height - 1) for x in range(1, maze.width - 1)
                      if maze.is_wall(x, y))  # fmt: skip
        x, y = editor.editor.cursor
        keys = ["right" if target[0] > x else "left"] * abs(target[0] - x)
        keys += ["down" if target[1] > y else "up"] * abs(target[1] - y)
        await pilot.press(*keys, "space")  # one wall taken away by hand
        await leave_the_editor_saving(pilot, tmp_path / "generated.txt")
        await pilot.press("l")
        await pilot.pause()
        assert objective_lines(screen)[1].startswith(
            "[X] edited the maze and kept it valid: edit 2 changed 1 block by hand"
        )

    run(app, body)


def capped_labs(tries: int):
    """The bundled labs, with drive-by-wire's question allowing ``tries`` answers."""
    found = []
    for lab in load_labs():
        if lab.id == "unity-simulator":
            exercises = tuple(
                replace(ex, questions=tuple(replace(q, max_tries=tries) for q in ex.questions))
                if ex.id == "drive-by-wire"
                else ex
                for ex in lab.exercises
            )
            lab = replace(lab, exercises=exercises)
        found.append(lab)
    return found


def test_a_question_out_of_tries_takes_no_answer_and_waits_for_the_instructor(
    tmp_path, monkeypatch
):
    monkeypatch.setattr(labs_screen, "load_labs", lambda: capped_labs(2))
    data = tmp_path / "data"
    create_instructor(data, "Dr Chen", "correct horse battery", kdf=FAST)
    app = lab_app(data)

    async def body(pilot: Pilot) -> None:
        screen = await open_exercise(pilot, DRIVE)
        field = screen.query_one("#q-tcp-port", Input)
        reason = field.parent.query_one(".question-reason")
        field.focus()
        await pilot.press("1", "2")
        await pilot.pause()
        assert str(reason.render()) == "press enter to try this answer: 2 of 2 tries left"
        await pilot.press("enter", "3", "enter")
        await pilot.pause()
        assert str(reason.render()) == (
            "[ ] not the expected answer (try 2 of 2): no tries left, the answer waits for the "
            "instructor"
        )
        assert field.disabled
        await pilot.press("backspace", "backspace", "5", "0", "enter")  # taken by nothing
        await pilot.pause()
        assert screen.lab_progress.answers[("unity-simulator", "drive-by-wire")] == {
            "tcp-port": "123"
        }
        assert objective_lines(screen)[-1] == (
            "[ ] question answered: no tries left, waiting for the instructor: tcp-port"
        )
        saved = app.store.progress.of("ana")[("unity-simulator", "drive-by-wire")]
        assert saved["tries"] == {"tcp-port": 2}
        (questions,) = [o for o in saved["objectives"] if o["kind"] == "questions"]
        assert questions["evidence"]["waiting"] == ["tcp-port"]
        screen.query_one("#labs-list").focus()
        await pilot.press("i")
        await pilot.pause()
        modal = app.screen
        assert isinstance(modal, SignoffModal)
        assert text(modal, "#signoff-evidence") == "out of tries, for you to judge: tcp-port"

    run(app, body)
