"""Every exercise of every bundled lab can be completed through the station, as a student would:
keys, the sensor panel, the maze editor, a completed starter FSM or a built-in algorithm, and a
scripted VIPLE program over the real endpoints. Wrong set-ups show the expected reason."""

from __future__ import annotations

import asyncio
from decimal import Decimal
from pathlib import Path

import pytest
from websockets.asyncio.server import serve

from tests.sessions import free_port
from tests.stations import run_to_exit
from tests.unit.test_labs_behaviour import renamed_and_reordered
from tests.waiting import DEADLINE, until
from workbench.control.station import LabStation
from workbench.labs.behaviour import BehaviourJudge
from workbench.labs.checks import ExerciseProgress, apply_setup, evaluate
from workbench.labs.model import Exercise, LabMaze, Objective, Question, load_labs
from workbench.sim.editing import MazeEditor
from workbench.viple.tcp_server import TcpConfig, TcpServer
from workbench.viple.ws_client import WsClient, WsConfig

LABS = {lab.id: lab for lab in load_labs()}
EXERCISES = [(lab.id, ex) for lab in LABS.values() for ex in lab.exercises]
MOVE = '{"servos":[{"isTurn":false,"servoId":-1,"servoSpeed":1}]}'
#: Robot Drive on the Web Simulator's wheel ports (3 and 5), both at 0.5
DRIVE = (
    '{"servos":[{"isTurn":false,"servoId":3,"servoSpeed":0.5},'
    '{"isTurn":false,"servoId":5,"servoSpeed":0.5}]}'
)
#: the values a student fills in to complete each starter
SOLUTIONS = {
    "starter-unity-wall-following": ["open_right=1.0", "front_blocked=0.9", "right_turn=90",
                                     "left_turn=-90"],
    "starter-unity-two-distance": ["front_blocked=1.0", "look_right=90", "look_left=-180",
                                   "back_right=180"],
    "starter-web-wall-following": ["base_distance=25", "open_margin=50", "turn90_time=1.5"],
    "starter-web-two-distance": ["front_blocked=25", "turn90_time=1.5", "turn180_time=3"],
}  # fmt: skip


def lab_of(ex: Exercise) -> str:
    return next(lab.id for lab in LABS.values() if any(e is ex for e in lab.exercises))


def fresh_station(ex: Exercise) -> LabStation:
    """A station with ``ex`` set up (its attempt begun)."""
    station = LabStation.open(ex.setup.maze.maze, ex.setup.profile, noise="off")
    apply_setup(station, ex.setup, lab=lab_of(ex), exercise=ex.id)
    return station


def run_on(
    station: LabStation, maze: LabMaze, algorithm: str, params: list[str] | None = None
) -> None:
    station.load_maze(maze.maze)
    station.select_algorithm(algorithm)
    if params:
        station.set_params(params)
    else:
        station.apply_algorithm_preset()
    run_to_exit(station)


def reach_exit(station: LabStation, ex: Exercise, obj: Objective) -> None:
    assert obj.maze is not None
    if "fsm" in obj.drivers:
        starter = ex.setup.controller
        assert starter.kind == "starter", "an fsm exit objective needs a starter to complete"
        station.select_algorithm(starter.value)
        run_on(station, obj.maze, starter.value, SOLUTIONS[station.algorithm.name])
    else:
        name = next(d.split(" ", 1)[1] for d in obj.drivers if d.startswith("algorithm "))
        run_on(station, obj.maze, name)


async def drive_over_tcp(station: LabStation) -> None:
    """A scripted VIPLE program in the Unity-simulator role: connect, move, leave."""
    async with TcpServer(station, TcpConfig(port=0)) as server:
        reader, writer = await asyncio.open_connection("127.0.0.1", server.port)
        writer.write(MOVE.encode() + b"\r\n")
        await writer.drain()
        await asyncio.wait_for(reader.readline(), DEADLINE)
        station.step(30)
        writer.close()
        await until(lambda: server.status.peer is None)
        station.step(1)


async def drive_over_ws(station: LabStation) -> None:
    """A scripted VIPLE WebSocket server: the workbench connects to it; it sends a move."""
    arrived: asyncio.Queue = asyncio.Queue()

    async def robot(ws) -> None:
        await ws.send(DRIVE)
        await arrived.put(await ws.recv())
        await ws.wait_closed()

    port = free_port()
    async with serve(robot, "127.0.0.1", port):
        client = WsClient(station, WsConfig(url=f"ws://127.0.0.1:{port}/"))
        await client.start()
        try:
            await asyncio.wait_for(arrived.get(), DEADLINE)
            await until(lambda: client.status.messages_in >= 1)
            assert client.status.invalid == 0, client.status.last_rejection
            station.step(30)
        finally:
            await client.close()
        station.step(1)


def viple_drive(station: LabStation, role: str) -> None:
    asyncio.run(drive_over_tcp(station) if role == "tcp" else drive_over_ws(station))


def answer(q: Question) -> str:
    """Find the accepted answer from the hashes alone, as the tests keep no answer key."""
    if q.choices:
        right = [c for c in q.choices if q.check(c)[0]]
        assert len(right) == 1, (q.id, right)
        return right[0]
    step = Decimal(q.step or "1")
    for k in range(int(-1000 / step), int(20000 / step)):
        text = str(k * step)
        if q.check(text)[0]:
            return text
    raise AssertionError(f"no answer to {q.id} in the searched range")


def complete(station: LabStation, ex: Exercise, folder: Path) -> dict[str, str]:
    """Every objective's work done on ``station`` (a drawn machine is written in ``folder``);
    the answers to its questions."""
    kinds = {o.kind for o in ex.objectives}
    for obj in ex.objectives:
        if obj.kind == "exit":
            reach_exit(station, ex, obj)
        elif obj.kind == "fsm-behaviour":
            drawn = folder / "drawn.yaml"  # drawn their own way
            drawn.write_text(renamed_and_reordered())
            station.select_algorithm(drawn)
            station.start()
            station.step(60)
        elif obj.kind == "compare":
            for maze in obj.mazes:
                for name in obj.algorithms:
                    run_on(station, maze, name)
    # back to the exercise's maze and sensors, in the same attempt
    station.load_maze(ex.setup.maze.maze)
    station.apply_sensors(ex.setup.sensors or station.sensors)
    for obj in ex.objectives:
        if obj.kind == "sensors":
            # the sensors fitted, and a run with them (fitting them is not the work)
            station.apply_sensors(obj.sensors)
            station.reset_robot()
            station.key("w")
            station.step(20)
            station.reset_robot()
        elif obj.kind == "keys":
            for key in obj.keys:
                station.key(key)
                station.step(10)
        elif obj.kind == "viple":
            viple_drive(station, obj.role)
    if "maze-edited" in kinds:
        maze = station.maze
        inner = next((x, y) for y in range(1, maze.height - 1) for x in range(1, maze.width - 1)
                     if maze.is_wall(x, y))  # fmt: skip
        editor = MazeEditor(maze)
        editor.toggle_wall(inner)  # one block taken away by hand, as in the editor
        station.put_edited_maze(editor.maze, editor.opened, hand_blocks=editor.hand_blocks())
    return {q.id: answer(q) for q in ex.questions}


@pytest.mark.parametrize(("lab_id", "ex"), EXERCISES, ids=[f"{lab}/{e.id}" for lab, e in EXERCISES])
def test_every_exercise_can_be_completed(lab_id, ex, tmp_path):
    station = fresh_station(ex)
    judge = BehaviourJudge(station.files, inline=True)
    before = evaluate(lab_id, ex, station, judge=judge)
    assert not before.passed
    answers = complete(station, ex, tmp_path)
    progress = evaluate(lab_id, ex, station, answers, judge=judge)
    failed = [(o.text, o.reason) for o in progress.objectives if not o.passed]
    assert failed == [], failed
    assert progress.passed
    assert ExerciseProgress.from_json(progress.to_json()) == progress


def reasons(lab_id: str, ex_id: str, station: LabStation | None = None, answers=None) -> list[str]:
    ex = LABS[lab_id].exercise(ex_id)
    progress = evaluate(lab_id, ex, station or fresh_station(ex), answers)
    return [("✓ " if o.passed else "✗ ") + o.reason for o in progress.objectives]


def test_web_sensors_left_at_the_default_show_what_is_missing():
    assert reasons("web-simulator", "sensors")[0] == (
        "✗ missing distance:3:left: fit them (sensor panel, o), then drive a run"
    )


def test_a_starter_run_as_given_does_not_count_as_getting_out():
    ex = LABS["unity-simulator"].exercise("wall-following")
    station = fresh_station(ex)
    station.start()
    station.step(60 * 120)
    assert reasons("unity-simulator", "wall-following", station)[:2] == [
        "✗ run 1 was driven by the lab starter starters/unity-wall-following.yaml, which comes "
        "with the workbench: drive a run with these sensors yourself (keys, VIPLE or your own "
        "program)",
        "✗ no run by viple or fsm has reached the exit of 'eRobotic lab maze' (unity) yet",
    ]


def test_the_wrong_sensor_for_local_best_on_the_web():
    ex = LABS["web-simulator"].exercise("local-best-activities")
    station = fresh_station(ex)
    station.apply_sensors(LABS["web-simulator"].exercise("wall-main").setup.sensors)
    assert reasons("web-simulator", "local-best-activities", station)[0] == (
        "✗ missing distance:3:front; not wanted distance:1:right, touch:2:front: fit them "
        "(sensor panel, o), then drive a run"
    )


def test_viple_in_the_unity_role_does_not_count_for_the_web_connection():
    ex = LABS["web-simulator"].exercise("connect")
    station = fresh_station(ex)
    viple_drive(station, "tcp")
    assert reasons("web-simulator", "connect", station)[0] == (
        "✗ VIPLE connected over tcp; this exercise needs WebSocket (the Web Simulator's)"
    )


def test_a_built_in_algorithm_does_not_stand_in_for_the_students_program():
    ex = LABS["web-simulator"].exercise("wall-main")
    station = fresh_station(ex)
    run_on(station, ex.setup.maze, "web-wall-following")
    assert reasons("web-simulator", "wall-main", station)[1] == (
        "✗ run 1 (algorithm web-wall-following) is the built-in algorithm "
        "algorithms/web-wall-following.yaml, which comes with the workbench, not your own "
        "program: complete it or write yours, and run that"
    )


def test_wrong_answers_are_counted_without_saying_which_value_is_right():
    got = reasons("maze-algorithms", "erobotic-rules", answers={
        "slower": "farthest-distance", "open-right": "100",
        "why-no-states": "the maze has no dead ends"})  # fmt: skip
    assert got[1] == "✗ 2 of 3 not right yet: slower, why-no-states"
