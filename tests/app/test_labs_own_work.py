"""In the app: an exercise's objectives pass only on its own work, and the sign-off names the
person whose work it rests on and shows at once."""

from __future__ import annotations

from textual.pilot import Pilot
from textual.widgets import Input, OptionList

from tests.integration.test_labs_completable import answer
from workbench.labs.model import LABS_DIR
from workbench.labs.signoff.instructors import KdfParams, create_instructor
from workbench.labs.store.store import Store
from workbench.tui.dialogs.path import PathDialog
from workbench.tui.dialogs.signoff import SignoffModal
from workbench.tui.screens.labs import LabsScreen
from workbench.tui.widgets.choices import Choices

from .labs_support import (
    DRIVE,
    evidence_lines,
    lab_app,
    objective_lines,
    open_exercise,
    signing_over,
    text,
    try_answer,
)
from .support import run

FAST = KdfParams(n=2**10, r=8, p=1)  # cheap scrypt for tests only
PASS = "correct horse battery"
READING = "unity-simulator/reading-wall-following"
RANKING = LABS_DIR.parent / "mazes" / "rank-local-best-wins.txt"


async def choose(pilot: Pilot, screen: LabsScreen, option_id: str) -> None:
    listing = screen.query_one("#labs-list", OptionList)
    listing.highlighted = listing.get_option_index(option_id)
    await pilot.pause()


def test_the_set_up_of_another_exercise_and_a_loaded_maze_pass_nothing(tmp_path):
    app = lab_app(tmp_path / "data", profile="web")

    async def body(pilot: Pilot) -> None:
        screen = await open_exercise(pilot, "maze-algorithms/erobotic-rules")
        await pilot.press("a")  # the first exercise of the first lab, set up
        await pilot.press("escape", "w", "a", "s", "d", "space")  # keys in that exercise
        await pilot.press("m")
        dialog = app.screen
        assert isinstance(dialog, PathDialog)
        dialog.query_one("#path", Input).value = str(RANKING)
        await pilot.press("enter")  # another bundled maze, loaded
        await pilot.pause()
        await pilot.press("l")
        await choose(pilot, screen, DRIVE)
        lines = objective_lines(screen)
        assert lines[0].startswith("[ ] drove with w, a, s, d and space: not set up yet")
        assert lines[1].startswith("[ ] edited the maze and kept it valid: not set up yet")
        await pilot.press("a")  # now drive-by-wire is set up: nothing done in it yet
        await pilot.press("escape", "m")
        app.screen.query_one("#path", Input).value = str(RANKING)
        await pilot.press("enter", "l")
        await pilot.pause()
        lines = objective_lines(screen)
        assert lines[0] == "[ ] drove with w, a, s, d and space: not used yet: w, a, s, d, space"
        assert lines[1].startswith("[ ] edited the maze and kept it valid: the maze has not been")
        saved = app.store.progress.of("ana")[("unity-simulator", "drive-by-wire")]
        assert [o["passed"] for o in saved["objectives"][:2]] == [False, False]

    run(app, body)


def test_the_sign_off_names_who_did_the_work_and_shows_the_moment_it_is_saved(tmp_path):
    """ana does reading-wall-following; drive-by-wire is then signed off with ben chosen to
    drive next (reading-wall-following); its sign-off still names ana, whose run it rests on."""
    data = tmp_path / "data"
    create_instructor(data, "Dr Chen", PASS, kdf=FAST)
    app = lab_app(data)

    async def sign(pilot: Pilot, driver: str) -> SignoffModal:
        """Open the sign-off, see whom it names as the driver, and sign."""
        await pilot.press("i")
        await pilot.pause()
        modal = app.screen
        assert isinstance(modal, SignoffModal)
        assert text(modal, "#signoff-state").startswith(f"ana and ben, driver {driver};")
        field = modal.query_one("#signoff-passphrase", Input)
        field.value = PASS
        field.focus()
        await pilot.press("enter")
        await signing_over(pilot, modal)
        return modal

    async def body(pilot: Pilot) -> None:
        screen = await open_exercise(pilot, READING)
        ex = screen.selected[1]
        await pilot.press("a")  # ana (the student) drives: nobody else was chosen
        station = app.station
        station.start()
        for _ in range(600):
            station.step(60)
            if station.runs:
                break
        assert station.runs[-1].ended == "exit" and station.runs[-1].person == "ana"
        for q in ex.questions:
            if q.choices:  # picked from its choices, as a student does
                screen.query_one(f"#q-{q.id}", Choices).focus()
                await pilot.press(*["down"] * q.choices.index(answer(q)), "enter")
            else:
                try_answer(screen, q.id, answer(q))
        await pilot.pause()
        assert screen.progress is not None and screen.progress.passed
        assert evidence_lines(screen)[0].startswith("run 1 by ana (algorithm right-wall)")

        await choose(pilot, screen, DRIVE)
        await pilot.press("a", "escape", "w", "a", "s", "d", "space")
        maze = station.maze
        inner = next((x, y) for y in range(1, maze.height - 1) for x in range(1, maze.width - 1)
                     if maze.is_wall(x, y))  # fmt: skip
        # the editor's report of one block taken away by hand
        station.put_edited_maze(maze.with_block(*inner, wall=False), maze, hand_blocks=1)
        await pilot.press("l")
        try_answer(screen, "tcp-port", "1350")
        await pilot.pause()
        await sign(pilot, "ana")
        # saved: the title and the list say so before the dialog is closed
        assert "signed off by Dr Chen on " in text(screen, "#labs-title")
        listing = screen.query_one("#labs-list", OptionList)
        assert str(listing.get_option(DRIVE).prompt).startswith("[*]")
        await pilot.click("#signoff-driver-1")  # ben drives next: reading-wall-following
        await pilot.pause()
        assert station.person == "ben"

        await choose(pilot, screen, READING)
        assert screen.driver == "ben"  # as chosen, though ana did the work
        await sign(pilot, "ana")
        with Store.open(data) as store:
            rows = {(r.lab, r.exercise): r for r in store.signoffs.of(student="ana")}
        row = rows[("unity-simulator", "reading-wall-following")]
        assert row.driver == "ana"
        objectives = row.metrics_value()["objectives"]
        run_evidence = next(o["evidence"] for o in objectives if o["kind"] == "exit")
        assert run_evidence["person"] == "ana" and run_evidence["run"] == 1
        assert run_evidence["attempt"] == station.attempts[0].id

    run(app, body)
