"""The console's students-by-exercises grid: where every student stands in every exercise of a
lab, at 80x24, in Unicode and in ASCII, following the store and scrolling."""

from __future__ import annotations

from textual.widgets import DataTable

from tests.waiting import until
from workbench.labs.checks import ObjectiveState
from workbench.labs.classview import read_request
from workbench.labs.model import load_labs
from workbench.labs.signoff.instructors import KdfParams, create_instructor
from workbench.labs.signoff.signing import sign_off
from workbench.labs.store.store import Store
from workbench.tui.console_app import ConsoleApp
from workbench.tui.screens.console import ConsoleScreen
from workbench.tui.screens.console_grid import GridScreen

from .console_support import (
    EXERCISE,
    LAB,
    WALL_MAIN,
    WEB_LAB,
    progress,
    save_progress,
    save_student,
    wall_main,
)
from .labs_support import text
from .support import screen_lines, sync

FAST = KdfParams(n=2**10, r=8, p=1)  # cheap scrypt for tests only
PASS = "correct horse battery"


def grid_rows(screen: GridScreen) -> dict[str, list[str]]:
    table = screen.query_one(DataTable)
    rows = [[str(c) for c in table.get_row_at(i)] for i in range(table.row_count)]
    return {row[0]: row[1:] for row in rows}


def headings(screen: GridScreen) -> list[str]:
    table = screen.query_one(DataTable)
    return [" ".join(str(c.label).split()) for c in table.columns.values()]


def a_class(data) -> None:
    """In drive-by-wire, ana passed and asked for sign-off, ben passed two objectives of
    three, and cat passed and has not asked; cat also did the Web lab's wall-main."""
    with Store.open(data) as store:
        save_student(store, "ana")
        save_student(store, "ben", passed=False)
        save_student(store, "cat")
        save_progress(store, "cat", wall_main("cat"))
        store.progress.set_place("cat", LAB, EXERCISE)
        store.queue.request("ana", "", "ana", LAB, EXERCISE)


async def open_grid(app: ConsoleApp, pilot) -> GridScreen:
    console = app.screen
    assert isinstance(console, ConsoleScreen)
    await until(lambda: console.view is not None, "the class")
    await pilot.press("g")
    grid = app.screen
    assert isinstance(grid, GridScreen)
    await pilot.pause()
    return grid


@sync
async def test_g_opens_the_grid_of_students_by_exercises(tmp_path):
    data = tmp_path / "data"
    a_class(data)
    app = ConsoleApp(Store.open(data), load_labs(), unicode=True)
    async with app.run_test(size=(80, 24)) as pilot:
        assert any("g Grid" in line for line in screen_lines(app))  # the key is shown
        grid = await open_grid(app, pilot)
        # the lab most of the class has open comes first, every exercise id whole
        assert text(grid, "#grid-title").startswith("Class by exercise, lab unity-simulator: 3")
        assert headings(grid) == [
            "Student",
            "drive-by- wire",
            "reading- wall- following",
            "wall- following",
            "local- best- activities",
            "local- best-main",
        ]
        rows = grid_rows(grid)
        assert rows["ana"][0] == "waiting" and rows["ben"][0] == "2/3" and rows["cat"][0] == "✓"
        assert rows["ana"][1:] == ["", "", "", ""]
        lines = screen_lines(app)
        assert all(len(line.rstrip()) <= 80 for line in lines)
        assert any(line.split()[:3] == ["ana", "waiting"] for line in lines if line.strip())
        await pilot.press("l")
        await pilot.pause()
        assert text(grid, "#grid-title").startswith("Class by exercise, lab web-simulator")
        assert grid_rows(grid)["cat"][headings(grid).index("wall-main") - 1] == "✓"
        await pilot.press("escape")
        await until(lambda: isinstance(app.screen, ConsoleScreen), "back at the console")


@sync
async def test_the_grid_follows_the_store_in_ascii(tmp_path):
    data = tmp_path / "data"
    a_class(data)
    create_instructor(data, "Dr Chen", PASS, kdf=FAST)
    app = ConsoleApp(Store.open(data), load_labs(), unicode=False)
    async with app.run_test(size=(80, 24)) as pilot:
        grid = await open_grid(app, pilot)
        assert grid_rows(grid)["cat"][0] == "ok"
        # ana is signed off (from another console) and a question of ben's waits for you
        with Store.open(data) as store:
            entry = store.queue.waiting()[0]
            request = read_request(store, entry, load_labs())
            sign_off(store, "Dr Chen", PASS, request.fields())
            store.queue.mark_signed(entry.id, "Dr Chen")
            waiting = progress(passed=False)
            waiting.objectives[-1] = ObjectiveState(
                "questions", "question answered", False, "1 of 1 not right yet",
                {"correct": 0, "of": 1, "tries": {"tcp-port": 3}, "waiting": ["tcp-port"]},
            )  # fmt: skip
            save_progress(store, "ben", waiting)
        grid.console.read_now()
        # word of each write may come before the next is made: wait for the read after both
        await until(
            lambda: grid_rows(grid)["ana"][0] == "signed" and grid_rows(grid)["ben"][0] == "2/3?",
            "the sign-off and the question",
        )
        assert "?: a question waits for you" in text(grid, "#grid-legend")
        assert all(line.isascii() for line in screen_lines(app))


@sync
async def test_a_class_taller_than_the_screen_scrolls(tmp_path):
    data = tmp_path / "data"
    names = [f"student-{n:02d}" for n in range(40)]
    with Store.open(data) as store:
        for name in names:
            save_progress(store, name, wall_main(name, digest=f"{len(name):02x}" * 32,
                                                attempt=name))  # fmt: skip
    app = ConsoleApp(Store.open(data), load_labs())
    async with app.run_test(size=(80, 24)) as pilot:
        grid = await open_grid(app, pilot)
        assert text(grid, "#grid-title").startswith(f"Class by exercise, lab {WEB_LAB}: 40")
        assert not any("student-39" in line for line in screen_lines(app))
        await pilot.press("ctrl+end")
        await pilot.pause()
        lines = screen_lines(app)
        assert any(line.split()[:1] == ["student-39"] for line in lines)
        column = headings(grid).index(WALL_MAIN)
        assert grid_rows(grid)["student-39"][column - 1] == "ok"
        # every student ran the same program: one hint names them all
        assert text(grid, "#grid-hints").startswith("same program wall.viple (")


@sync
async def test_a_class_of_one_is_counted_as_one_student(tmp_path):
    data = tmp_path / "data"
    with Store.open(data) as store:
        save_progress(store, "ana", progress())
    app = ConsoleApp(Store.open(data), load_labs())
    async with app.run_test(size=(80, 24)) as pilot:
        grid = await open_grid(app, pilot)
        title = text(grid, "#grid-title")
        assert ": 1 student" in title and "students" not in title, title
