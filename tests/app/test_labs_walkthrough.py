"""A pair of students does every lab exercise in one app, and the instructor signs each off.

Ana and Ben open the labs (l), pick each exercise in turn, set it up (a) and do the work the
way the app offers it: drive keys, the sensor panel, the maze editor, the maze key, the
algorithm dialog (built-ins, and the starter FSMs completed in its parameter editor), a
VIPLE program on the WebSocket server the app connects to, and the question fields. Every
objective must show as passed ([X] in ASCII mode) on the labs screen without an override;
then the instructor signs the exercise off (i) and the pair swaps the driver. At the end the
store holds one signed record per exercise, the records verify and the gradebook has a row per
student per exercise.

All of it at 80x24 in ASCII mode, read off the terminal as the students see it: every
objective's line (its text and its reason) can be read whole at some scroll position of the
exercise pane, and the figures of every finished run (run panel, run record and the evidence the
sign-off keeps) are those ``workbench run`` gives for the same maze, profile, sensors, seed,
noise and parameters. One test per lab, so the three run side by side.
"""

from __future__ import annotations

import asyncio
import csv
from pathlib import Path

import pytest
from textual.pilot import Pilot
from textual.widgets import Input, Markdown, OptionList, Select, Static
from websockets.asyncio.server import serve

from tests.app.labs_support import objective_lines, open_labs, signing_over, try_answer
from tests.app.test_fsm_editor import write_right_wall
from tests.integration.test_labs_completable import DRIVE, SOLUTIONS, answer
from tests.sessions import free_port
from tests.waiting import DEADLINE, until
from workbench.cli import main
from workbench.control.headless import AlgorithmPilot, RunSpec
from workbench.control.headless import run as headless_run
from workbench.fsm.algorithms import list_algorithms
from workbench.labs.model import Exercise, Lab, LabMaze, Objective, load_labs
from workbench.labs.signoff.instructors import KdfParams, create_instructor
from workbench.labs.signoff.roster import load_roster, roster_path
from workbench.labs.signoff.verify import verify_all
from workbench.labs.store.store import Store
from workbench.sim.mazeio import save_maze
from workbench.sim.profiles import get_profile
from workbench.tui.app import WorkbenchApp, make_app
from workbench.tui.dialogs.algorithm import AlgorithmModal
from workbench.tui.dialogs.path import PathDialog
from workbench.tui.dialogs.sensor_ports import SensorPortsModal
from workbench.tui.dialogs.signoff import SignoffModal
from workbench.tui.plain import prose
from workbench.tui.screens.editor import EditorScreen
from workbench.tui.screens.fsm_editor import FsmEditorScreen
from workbench.tui.screens.labs import LabsScreen
from workbench.tui.screens.main import MainScreen
from workbench.tui.widgets.choices import Choices
from workbench.tui.widgets.param_editor import ParamEditor
from workbench.tui.widgets.sensor_row_editor import SensorRowEditor
from workbench.tui.widgets.text import degrees, number
from workbench.viple.tcp_server import TcpConfig
from workbench.viple.ws_client import WsConfig
from workbench.wire.settings import AppSettings

from .support import run, run_panel, said, screen_lines

FAST = KdfParams(n=2**10, r=8, p=1)  # cheap scrypt for tests only
INSTRUCTOR = "Dr Chen"
PASS = "correct horse battery"
PAIR = ("ana", "ben")
LABS = load_labs()
#: the exercise pane's first column at 80x24 (the lab list is 28 wide, then one blank)
PANE = 29
#: measures of a run the app shows and ``workbench run`` prints
MEASURES = ("reached_exit", "exit_time", "distance", "turn_degrees", "turns", "collisions")


class Walkthrough:
    """The pair at the keyboard of one app."""

    def __init__(self, pilot: Pilot, tmp: Path) -> None:
        self.pilot = pilot
        self.app: WorkbenchApp = pilot.app  # type: ignore[assignment]
        self.tmp = tmp
        #: the built-in algorithms picked in the dialog so far
        self.met: set[str] = set()
        #: ``workbench run``'s metrics of each run to the exit, by (maze digest, driver, profile)
        self.headless: dict[tuple[str, str, str], dict] = {}

    @property
    def station(self):
        return self.app.station

    async def press(self, *keys: str) -> None:
        await self.pilot.press(*keys)
        await self.pilot.pause()

    # -- screens ---------------------------------------------------------------------------
    async def labs(self) -> LabsScreen:
        if not isinstance(self.app.screen, LabsScreen):
            return await open_labs(self.pilot)
        screen = self.app.screen
        assert isinstance(screen, LabsScreen)
        return screen

    async def main_screen(self) -> MainScreen:
        if isinstance(self.app.screen, LabsScreen):
            await self.press("escape")
        screen = self.app.screen
        assert isinstance(screen, MainScreen), screen
        return screen

    async def open(self, lab: Lab, ex: Exercise) -> LabsScreen:
        screen = await self.labs()
        listing = screen.query_one("#labs-list", OptionList)
        listing.highlighted = listing.get_option_index(f"{lab.id}/{ex.id}")
        await self.pilot.pause()
        # the instructions are parsed in a thread, then mounted, under the lock of their
        # Markdown widget: wait for that, so the objectives below them are where they stay
        async with screen.query_one("#labs-instructions", Markdown).lock:
            pass
        await self.pilot.pause()
        assert str(screen.query_one("#labs-title").render()) == f"{lab.title}: {ex.title}"
        return screen

    # -- the work --------------------------------------------------------------------------
    async def load_maze(self, lab_maze: LabMaze) -> None:
        """The maze key: type the file's path in the dialog."""
        if self.station.maze.same_layout(lab_maze.maze):
            return
        await self.main_screen()
        await self.press("m")
        dialog = self.app.screen
        assert isinstance(dialog, PathDialog)
        dialog.query_one("#path", Input).value = str(lab_maze.path)
        await self.press("enter")
        assert isinstance(self.app.screen, MainScreen)
        assert self.station.maze.same_layout(lab_maze.maze), said(self.app)

    async def algorithm_dialog(self) -> AlgorithmModal:
        await self.main_screen()
        await self.press("g")
        modal = self.app.screen
        assert isinstance(modal, AlgorithmModal)
        return modal

    async def run_builtin(self, name: str) -> None:
        """A built-in algorithm: picked in the algorithm dialog the first time the pair meets
        it, its sensors fitted (f), started; later through the station, as the dialog does."""
        station = self.station
        if name in self.met:
            station.select_algorithm(name)
            station.apply_algorithm_preset()
            station.start()
            await self.run_to_exit()
            return
        self.met.add(name)
        modal = await self.algorithm_dialog()
        options = modal.query_one("#alg-builtins", OptionList)
        options.highlighted = list_algorithms().index(name)
        options.focus()
        await self.press("enter")
        assert station.algorithm is not None and station.algorithm.name == name
        if station.missing_sensors():
            await self.press("f")  # fit the sensors the algorithm reads
        await self.start(modal)

    async def run_starter(self, path: str) -> None:
        """The exercise's starter FSM, completed in the parameter editor and started; once it
        is complete, x runs it again (on another maze, say)."""
        station = self.station
        definition = station.algorithm
        if definition is not None and definition.source == path and self.completed(definition):
            await self.main_screen()
            await self.press("x")
            assert station.driving is not None, said(self.app)
            await self.run_to_exit()
            return
        modal = await self.algorithm_dialog()
        if definition is None or definition.source != path:
            field = modal.query_one("#alg-path", Input)
            field.value = path
            await field.action_submit()
            await self.pilot.pause()
        definition = station.algorithm
        assert definition is not None and definition.source == path
        editors = {e.parameter.name: e for e in modal.query(ParamEditor)}
        for item in SOLUTIONS[definition.name]:
            name, value = item.split("=")
            editors[name].query_one(Input).value = value
        await self.pilot.pause()
        assert self.completed(definition), station.params()
        await self.start(modal)

    def completed(self, definition) -> bool:
        params = self.station.params()
        return all(
            params[name] == float(value)
            for name, value in (item.split("=") for item in SOLUTIONS[definition.name])
        )

    async def start(self, modal: AlgorithmModal) -> None:
        await self.pilot.click("#alg-start")
        await self.pilot.pause()
        assert self.app.screen is not modal, str(modal.query_one("#alg-error").render())
        assert self.station.driving is not None
        await self.run_to_exit()

    async def run_to_exit(self) -> None:
        """Step the running algorithm in large batches until its run ends."""
        station = self.station
        done = len(station.runs)
        for _ in range(600):
            station.step(60)
            if len(station.runs) > done:
                break
        last = station.runs[-1]
        assert len(station.runs) > done and last.ended == "exit", (last, said(self.app))
        await self.pilot.pause()
        self.same_as_headless()

    def same_as_headless(self) -> None:
        """The finished run's figures, in the run record and on the run panel, are those of
        ``workbench run`` for the same maze, profile, sensors, seed, noise and parameters."""
        station = self.station
        last = station.runs[-1]
        maze = self.tmp / f"maze-{last.maze_digest[:12]}.txt"
        save_maze(maze, station.maze)
        definition = station.algorithm
        assert definition is not None
        spec = RunSpec(
            maze=str(maze),
            pilot=AlgorithmPilot(
                definition.source if definition.source else definition.name,
                tuple(f"{k}={v!r}" for k, v in station.params().items()),
            ),
            profile=station.profile,
            sensors=tuple(str(s) for s in station.sensors),
            seed=station.seed,
            noise="off",
        )
        want = headless_run(spec).metrics
        got = last.metrics.as_dict()
        for key in MEASURES:
            assert got[key] == pytest.approx(want[key], abs=1e-9), (key, got, want)
        self.headless[(last.maze_digest, str(last.driver), last.profile)] = want
        # the run panel, as the students read it after the run
        self.app.refresh_views()
        panel = run_panel(self.app)
        unit = get_profile(station.profile).unit
        shown = " ".join(panel.split())
        for text in (
            f"out at {want['exit_time']:.1f} s",
            f"distance {number(want['distance'], unit)} {unit}",
            f"turned {degrees(want['turn_degrees'], False)}; {want['turns']} turn",
            f"collisions {want['collisions']}",
        ):
            assert text in shown, (text, panel)

    def evidence_as_headless(self, screen: LabsScreen, ex: Exercise) -> None:
        """The runs the sign-off keeps as evidence carry ``workbench run``'s figures."""
        assert screen.progress is not None
        runs = []
        for state in screen.progress.objectives:
            if "metrics" in state.evidence:
                runs.append(state.evidence)
            runs.extend(state.evidence.get("runs", []))
        kinds = [o.kind for o in ex.objectives]
        compared = sum(len(o.mazes) * len(o.algorithms) for o in ex.objectives)
        judged = kinds.count("fsm-behaviour")
        assert len(runs) == kinds.count("exit") + kinds.count("sensors") + compared + judged, runs
        for evidence in runs:
            if evidence["driver"] == "keys":  # a drive with the sensors: no run to repeat
                continue
            want = self.headless[(evidence["maze_digest"], evidence["driver"], evidence["profile"])]
            for key in MEASURES:
                assert evidence["metrics"][key] == pytest.approx(want[key], abs=1e-9), key

    async def reach_exit(self, ex: Exercise, obj: Objective) -> None:
        assert obj.maze is not None
        await self.load_maze(obj.maze)
        if "fsm" in obj.drivers:
            assert ex.setup.controller.kind == "starter"
            await self.run_starter(ex.setup.controller.value)
        else:
            name = next(d.split(" ", 1)[1] for d in obj.drivers if d.startswith("algorithm "))
            await self.run_builtin(name)

    async def compare(self, obj: Objective) -> None:
        for lab_maze in obj.mazes:
            await self.load_maze(lab_maze)
            for name in obj.algorithms:
                await self.run_builtin(name)

    async def draw_fsm(self) -> None:
        """The FSM editor (F): the machine drawn through its forms, saved, run to the exit
        (ctrl+r); the labs screen then waits for the comparison with the reference."""
        await self.main_screen()
        await self.press("F")
        editor = self.app.screen
        assert isinstance(editor, FsmEditorScreen)
        await write_right_wall(self.pilot, editor, whole=True)
        await self.press("ctrl+r")
        assert isinstance(self.app.screen, PathDialog)
        self.app.screen.query_one("#path", Input).value = str(self.tmp / "drawn.yaml")
        await self.press("enter")
        assert self.station.driving is not None, editor.status
        await self.run_to_exit()
        await self.press("escape")
        screen = await self.labs()
        await until(lambda: screen.lab_progress.judge is not None and
                    not screen.lab_progress.judge.busy, "the machine compared")  # fmt: skip

    async def drive_keys(self, obj: Objective) -> None:
        await self.main_screen()
        for key in obj.keys:
            await self.press(key)
            self.station.step(10)

    async def set_sensors(self, obj: Objective) -> None:
        """The sensor panel (o): kinds, ports and mounts typed in its rows, then Apply."""
        await self.main_screen()
        await self.press("o")
        modal = self.app.screen
        assert isinstance(modal, SensorPortsModal)
        wanted = list(obj.sensors)
        for row in modal.query(SensorRowEditor):
            kind = row.query_one(".row-kind", Select).value
            spec = next((s for s in wanted if s.kind == kind), None)
            if spec is None:
                row.query_one(".row-mount", Select).value = "none"
                continue
            wanted.remove(spec)
            row.query_one(".row-port", Input).value = str(spec.port)
            row.query_one(".row-mount", Select).value = spec.mount
        await self.pilot.pause()
        assert wanted == []
        await self.pilot.click("#ports-apply")
        await self.pilot.pause()
        assert str(modal.query_one("#ports-status").render()).startswith("applied:")
        await self.press("escape")
        assert {str(s) for s in self.station.sensors} == {str(s) for s in obj.sensors}

    async def passes(self, lab: Lab, ex: Exercise, obj: Objective) -> bool:
        screen = await self.open(lab, ex)
        assert screen.progress is not None
        return next(o for o in screen.progress.objectives if o.text == obj.text).passed

    async def drive_a_run(self) -> None:
        """Back to the start (r) and a short drive with the keys: a run on the sensors."""
        await self.main_screen()
        await self.press("r", "w")
        self.station.step(20)
        await self.press("space")

    async def edit_maze(self) -> None:
        """The maze editor: open an inner wall, save the maze as a new file, go back."""
        await self.main_screen()
        await self.press("e")
        editor = self.app.screen
        assert isinstance(editor, EditorScreen)
        maze = self.station.maze
        target = next((x, y) for y in range(1, maze.height - 1) for x in range(1, maze.width - 1)
                      if maze.is_wall(x, y))  # fmt: skip
        x, y = editor.editor.cursor
        keys = ["right" if target[0] > x else "left"] * abs(target[0] - x)
        keys += ["down" if target[1] > y else "up"] * abs(target[1] - y)
        await self.press(*keys, "space")
        assert editor.dirty
        await self.press("a")  # save as: a file of the students' own
        dialog = self.app.screen
        assert isinstance(dialog, PathDialog)
        dialog.query_one("#path", Input).value = str(self.tmp / "edited.txt")
        await self.press("enter")
        assert not editor.dirty, editor.status
        await self.press("escape")
        assert isinstance(self.app.screen, MainScreen)
        assert not self.station.maze.same_layout(maze)

    async def answer_questions(self, ex: Exercise) -> None:
        screen = await self.labs()
        for q in ex.questions:
            if q.choices:  # picked: the set takes the focus, the keys move to the choice
                screen.query_one(f"#q-{q.id}", Choices).focus()
                await self.press(*["down"] * q.choices.index(answer(q)), "enter")
            else:
                try_answer(screen, q.id, answer(q))
        await self.pilot.pause()
        reasons = [str(s.render()) for s in screen.query(".question-reason").results(Static)]
        assert reasons == ["[X] correct (1 try)"] * len(ex.questions), reasons

    async def do(self, lab: Lab, ex: Exercise) -> None:
        """Everything the exercise asks, in the order a pair would do it."""
        kinds = [o.kind for o in ex.objectives]
        for obj in ex.objectives:
            if obj.kind == "exit":
                await self.reach_exit(ex, obj)
            elif obj.kind == "compare":
                await self.compare(obj)
            elif obj.kind == "fsm-behaviour":
                await self.draw_fsm()
        if {"keys", "maze-edited"} & set(kinds):  # those work on the exercise's own maze
            await self.load_maze(ex.setup.maze)
        for obj in ex.objectives:
            if obj.kind == "sensors":
                if {str(s) for s in self.station.sensors} != {str(s) for s in obj.sensors}:
                    await self.set_sensors(obj)
                if not await self.passes(lab, ex, obj):  # a run with them is the work
                    await self.drive_a_run()
            elif obj.kind == "keys":
                await self.drive_keys(obj)
            elif obj.kind == "maze-edited":
                await self.edit_maze()
        await self.answer_questions(ex)

    # -- reading the terminal ----------------------------------------------------------------
    async def objectives_readable(self, screen: LabsScreen) -> None:
        """Scroll the exercise pane with the keys, from the top down past the objectives (or
        until every objective has been read), and read the terminal at each position: every
        objective's line (mark, text and reason) must be seen whole in one view, words
        unbroken, in plain ASCII."""
        assert screen.progress is not None
        marks = screen.marks
        wanted = {
            " ".join(prose(f"{marks.passed if o.passed else marks.failed} {o.text}: {o.reason}",
                           False).split())
            for o in screen.progress.objectives
        }  # fmt: skip
        pane = screen.query_one("#labs-scroll")
        objectives = screen.query_one("#labs-objectives")
        pane.focus()
        pane.scroll_home(animate=False)
        await self.pilot.pause()
        views = []
        unseen = set(wanted)
        while True:
            lines = screen_lines(self.app)
            assert all(line.isascii() for line in lines), "\n".join(lines)
            views.append(" ".join(" ".join(line[PANE:].split()) for line in lines[:-2]))
            unseen = {text for text in unseen if text not in views[-1]}
            # (the pane's layout as it is now: a busy machine may lay it out after the pause)
            past = min(objectives.region.height, pane.max_scroll_y)
            if not unseen or pane.scroll_y >= past or len(views) > 200:
                break  # every line read whole, or scrolled past the objectives
            await self.press("down")
        assert not unseen, (unseen, views)
        screen.query_one("#labs-list").focus()
        await self.pilot.pause()

    # -- sign-off --------------------------------------------------------------------------
    async def sign_off(self, screen: LabsScreen, ex: Exercise, next_driver: str) -> None:
        self.evidence_as_headless(screen, ex)
        await self.press("i")
        modal = self.app.screen
        assert isinstance(modal, SignoffModal)
        assert "all objectives pass" in str(modal.query_one("#signoff-state").render())
        modal.query_one("#signoff-note", Input).value = "seen at the station"
        field = modal.query_one("#signoff-passphrase", Input)
        field.value = PASS
        field.focus()
        await self.press("enter")
        await signing_over(self.pilot, modal)
        done = str(modal.query_one("#signoff-done").render())
        assert done == f"Signed off by {INSTRUCTOR}.", str(
            modal.query_one("#signoff-status").render()
        )
        await self.pilot.click(f"#signoff-driver-{PAIR.index(next_driver)}")
        await self.pilot.pause()
        assert self.app.screen is screen
        assert screen.driver == next_driver


def objectives(screen: LabsScreen) -> list[str]:
    return objective_lines(screen)


async def viple_over_websocket(w: Walkthrough, screen: LabsScreen, lab: Lab, ex: Exercise) -> None:
    """The students start their VIPLE program (a WebSocket server), then set the exercise up:
    the set-up starts the app's WebSocket client, which connects; the program drives."""
    arrived: asyncio.Queue[str] = asyncio.Queue()

    async def program(ws) -> None:
        await ws.send(DRIVE)
        await arrived.put(await ws.recv())
        await ws.wait_closed()

    url = w.app._viple_configs[1].url  # the URL the app's WebSocket client uses
    port = int(url.rsplit(":", 1)[1].strip("/"))
    async with serve(program, "127.0.0.1", port) as server:
        assert w.app.endpoints is None or w.app.endpoints.ws is None
        await w.press("a")
        await asyncio.wait_for(arrived.get(), DEADLINE)  # the app connected and sent a report
        client = w.app.endpoints.ws
        assert client is not None
        await until(lambda: client.status.messages_in >= 1, "the program's command taken")
        assert client.status.invalid == 0, client.status.last_rejection
        w.station.step(30)  # the program's move, simulated
        await w.pilot.pause()
        assert w.station.viple and w.station.viple[-1].drove
        server.close()  # the students stop their program
    await until(lambda: not str(w.station.session.driver).startswith("VIPLE"), "VIPLE gone")
    w.station.step(1)
    await w.open(lab, ex)


@pytest.mark.long
@pytest.mark.parametrize("lab", LABS, ids=[lab.id for lab in LABS])
def test_a_pair_completes_and_signs_off_every_exercise_in_the_app(tmp_path, lab):
    data = tmp_path / "data"
    kept_roster = tmp_path / "instructor" / "roster.json"  # the instructor's own copy
    create_instructor(data, INSTRUCTOR, PASS, kdf=FAST, trusted=kept_roster)
    # paused and noise off: every run is stepped by the test, in large batches, and comes out
    # the same each time; the app ticks only to draw, so slowly
    app = make_app(
        AppSettings(
            paused=True, noise="off", tick_hz=2, student="ana", partner="ben", data_dir=data
        )
    )

    async def body(pilot: Pilot) -> None:
        assert app.endpoints is None  # none asked for at start: a set-up starts what it needs
        # ... on free ports here, so the test never depends on the course's 1350 / 8124
        app._viple_configs = (
            TcpConfig(port=free_port()),
            WsConfig(url=f"ws://127.0.0.1:{free_port()}/", retry_seconds=0.2),
        )
        w = Walkthrough(pilot, tmp_path)
        for n, ex in enumerate(lab.exercises):
            driver = PAIR[n % 2]
            screen = await w.open(lab, ex)
            assert screen.driver == driver, (lab.id, ex.id)
            assert not all(line.startswith("[X]") for line in objectives(screen))
            await w.objectives_readable(screen)  # what is still to do, with its reasons
            if ex.setup.controller.kind == "viple":
                await viple_over_websocket(w, screen, lab, ex)
            else:
                await w.press("a")
            message = str(screen.query_one("#labs-message").render())
            assert message.startswith(f"set up: {ex.setup.profile}"), message
            assert w.station.profile == ex.setup.profile
            await w.do(lab, ex)
            screen = await w.labs()
            lines = objectives(screen)
            assert len(lines) == len(ex.objectives)
            assert all(line.startswith("[X]") for line in lines), (lab.id, ex.id, lines)
            assert screen.progress is not None and screen.progress.passed
            await w.objectives_readable(screen)  # the passed lines, with their figures
            await w.sign_off(screen, ex, PAIR[(n + 1) % 2])
        listing = screen.query_one("#labs-list", OptionList)
        for ex in lab.exercises:
            assert str(listing.get_option(f"{lab.id}/{ex.id}").prompt).startswith("[*]")
        await pilot.press("ctrl+q")

    run(app, body)

    with Store.open(data) as store:
        rows = sorted(store.signoffs.of(), key=lambda r: r.id)
        roster = load_roster(roster_path(data))
        verdicts = verify_all(store, roster)
    assert [(r.lab, r.exercise) for r in rows] == [(lab.id, ex.id) for ex in lab.exercises]
    assert not any(r.override for r in rows)
    assert [r.driver for r in rows] == [PAIR[n % 2] for n in range(len(rows))]
    assert {(r.student, r.partner, r.instructor) for r in rows} == {("ana", "ben", INSTRUCTOR)}
    assert all(v.ok for v in verdicts), [(v.row.exercise, v.problems) for v in verdicts]

    trusted = ["--roster", str(kept_roster), "--data-dir", str(data)]
    assert main(["signoff", "verify", *trusted]) == 0
    gradebook = tmp_path / "gradebook.csv"
    assert main(["signoff", "export", "--csv", str(gradebook), *trusted]) == 0
    with gradebook.open(newline="") as f:
        table = list(csv.DictReader(f))
    assert len(table) == 2 * len(lab.exercises)
    assert {(r["student"], r["lab"], r["exercise"]) for r in table} == {
        (who, lab.id, ex.id) for who in PAIR for ex in lab.exercises
    }
    assert {r["override"] for r in table} == {"no"}
