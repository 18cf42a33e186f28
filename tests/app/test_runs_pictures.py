"""Pictures from the runs screen, the replay and the console's evidence, at 80x24: saved in
the workspace's pictures/ folder in a thread, the screen saying where (or why not)."""

from __future__ import annotations

from tests.app.runs_support import BEND, run_algorithms
from tests.app.support import sync
from tests.app.test_runs import SIZE, Host, text
from tests.pictures.records import BEND as BEND_TEXT
from tests.pictures.svg import marks, path_points, texts
from tests.waiting import until
from workbench.control.station import LabStation
from workbench.files.workspace import FileAccess
from workbench.sim.mazeio import load_maze
from workbench.sim.replay import load_replay
from workbench.tui.screens.replay import ReplayScreen
from workbench.tui.screens.runs import RunsScreen


def _served(tmp_path) -> LabStation:
    """A served student's station: files in a workspace, runs recorded in its ~/runs."""
    workspace = tmp_path / "ws"
    files = FileAccess.confined_to(workspace)
    station = LabStation.open(
        BEND, "erobotic", noise="off", record_dir=str(workspace / "runs"), files=files
    )
    return run_algorithms(station, "right-wall", "two-distance-local-best")


def _status(screen: RunsScreen) -> str:
    return screen.status


async def _saved(screen: RunsScreen, *words: str) -> str:
    """The runs screen's line once it says the picture was saved, with ``words`` in it."""

    def said() -> str:
        line = screen.status
        return line if "saved" in line and all(w in line for w in words) else ""

    return await until(said, f"a line saying a picture with {words} was saved")


@sync
async def test_the_runs_screen_saves_the_chosen_runs_picture(tmp_path):
    station = _served(tmp_path)
    workspace = station.files.workspace
    screen = RunsScreen(station)
    shown: list[str] = []
    status = screen._status

    def logged(text: str, error: bool = False) -> None:
        shown.append(text)
        status(text, error)

    screen._status = logged  # type: ignore[method-assign]
    app = Host(screen)
    async with app.run_test(size=SIZE) as pilot:
        await pilot.press("down", "p")
        said = await _saved(screen, "run 2")
        # the screen said it was drawing before it said where the picture went
        assert shown == ["drawing the path of run 2...", said]
        record = station.runs[1].record
        name = f"pictures/{record.rsplit('/', 1)[-1].removesuffix('.jsonl')}-path.svg"
        picture = workspace / name
        assert f"saved the path of run 2 in ~/{name}" in said
        assert f"download it with sftp or scp (get {name})" in said
        svg = picture.read_bytes()
        assert path_points(svg, "robot-path") == len(load_replay(record))
        assert "two-distance-local-best" in texts(svg)
        # the message is on the screen, whole enough to read the file's name
        assert "saved the path of run 2" in text(screen.query_one("#runs-status"))

        await pilot.press("c")
        said = await _saved(screen, "side-by-side")
        assert "pictures/Bend-2-runs.svg" in said
        svg = (workspace / "pictures" / "Bend-2-runs.svg").read_bytes()
        assert path_points(svg, "robot-path-1") > 0 and path_points(svg, "robot-path-2") > 0

        await pilot.press("t")
        await _saved(screen, "plot over time")
        assert (workspace / name.replace("-path.svg", "-time.svg")).is_file()


@sync
async def test_a_run_without_a_record_has_no_picture(tmp_path):
    station = LabStation.open(BEND, "erobotic", noise="off")
    run_algorithms(station, "right-wall")
    screen = RunsScreen(station)
    async with Host(screen).run_test(size=SIZE) as pilot:
        await pilot.press("p")
        assert "run 1 was not recorded" in screen.status
        await pilot.press("c")
        assert "no recorded run on this maze" in screen.status


@sync
async def test_a_picture_that_cannot_be_saved_says_why(tmp_path):
    station = _served(tmp_path)
    workspace = station.files.workspace
    (workspace / "pictures").write_text("a file where the folder would be\n")
    screen = RunsScreen(station)
    async with Host(screen).run_test(size=SIZE) as pilot:
        await pilot.press("p")
        said = await until(lambda: "no picture" in screen.status and screen.status, "refusal")
        assert "~/pictures" in said and "Traceback" not in said
        assert (workspace / "pictures").read_text() == "a file where the folder would be\n"


@sync
async def test_the_replay_saves_the_picture_with_the_beams_at_this_tick(tmp_path):
    station = _served(tmp_path)
    workspace = station.files.workspace
    record = station.runs[0].record
    replay = load_replay(record)
    screen = ReplayScreen(record, replay, mazes=(station.maze,), files=station.files)
    async with Host(screen).run_test(size=SIZE) as pilot:
        await pilot.press(*["pagedown"] * 3)
        t = replay.frame().t
        await pilot.press("p")
        said = await until(lambda: "saved" in screen.said and screen.said, "saved")
        name = record.rsplit("/", 1)[-1].removesuffix(".jsonl")
        assert f"~/pictures/{name}-path.svg" in said
        svg = (workspace / "pictures" / f"{name}-path.svg").read_bytes()
        assert f"t {t:.1f} s" in texts(svg)
        assert path_points(svg, "beams-1") == 4  # two distance sensors, a beam each
        assert marks(svg, "collisions") == 0
        assert "saved the path of this run" in text(screen.query_one("#replay-said"))


@sync
async def test_the_console_saves_the_evidence_runs_picture(tmp_path, monkeypatch):
    from textual.widgets import OptionList

    from tests.app.console_support import EXERCISE, LAB, save_student
    from tests.pictures.records import record_of
    from workbench.labs.model import load_labs
    from workbench.labs.store.store import Store
    from workbench.tui.console_app import ConsoleApp
    from workbench.tui.screens.console import ConsoleScreen
    from workbench.tui.screens.console_request import RequestScreen

    monkeypatch.chdir(tmp_path)  # the instructor's own folder: pictures/ goes there
    (tmp_path / "ana").mkdir()
    record = record_of(tmp_path / "ana", text=BEND_TEXT)
    data = tmp_path / "data"
    with Store.open(data) as store:
        save_student(store, "ana", record=str(record))
        store.progress.set_place("ben", LAB, EXERCISE)
        store.queue.request("ana", "ben", "ben", LAB, EXERCISE)
    app = ConsoleApp(Store.open(data), load_labs())
    async with app.run_test(size=SIZE) as pilot:
        await until(lambda: isinstance(app.screen, ConsoleScreen), "the console")
        queue = lambda: app.screen.query_one("#console-queue", OptionList).options  # noqa: E731
        await until(lambda: len(queue()) == 1, "the request")
        await pilot.press("enter")
        request = app.screen
        assert isinstance(request, RequestScreen)
        await until(lambda: request.request is not None, "the saved progress")
        await pilot.press("ctrl+g")
        picture = tmp_path / "pictures" / f"{record.stem}-path.svg"
        await until(picture.is_file, "the picture")
        await until(
            lambda: "saved the path of run 3" in str(request.query_one("#request-status").render()),
            "the message",
        )
        svg = picture.read_bytes()
        assert path_points(svg, "robot-path") == len(load_replay(record))


@sync
async def test_a_run_whose_maze_is_gone_says_how_to_draw_it(tmp_path):
    station = _served(tmp_path)
    station.load_maze(load_maze("mazes/web.txt"))  # Bend was never a file: only the station had it
    screen = RunsScreen(station)
    async with Host(screen).run_test(size=SIZE) as pilot:
        await pilot.press("a", "p")
        said = await until(lambda: "no picture" in screen.status and screen.status, "refusal")
        assert "the maze cannot be drawn" in said
        assert "load that maze on the workbench (m) and save the picture again" in said
        assert "--maze" not in said
    assert not (station.files.workspace / "pictures").exists() or not any(
        (station.files.workspace / "pictures").iterdir()
    )
