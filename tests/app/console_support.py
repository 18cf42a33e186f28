"""What the console tests share: a class's saved progress in a store, and waiting for screens."""

from __future__ import annotations

import json
from pathlib import Path

from workbench.labs.checks import ExerciseProgress, ObjectiveState
from workbench.labs.model import load_labs
from workbench.labs.store.store import Store
from workbench.sim.record import FORMAT, file_sha256

LAB, EXERCISE = "unity-simulator", "drive-by-wire"


def write_record(path: Path) -> Path:
    """A small run record (ten ticks along a corridor) the replay screen can open."""
    lines = [{"type": "header", "format": FORMAT, "cell": 10.0}]
    lines += [{"t": round(i * 0.05, 4), "pose": [15.0 + i, 15.0, 0.0]} for i in range(10)]
    lines.append({"type": "summary", "reached_exit": True})
    path.write_text("".join(json.dumps(obj) + "\n" for obj in lines))
    return path


def progress(passed: bool = True, record: str = "") -> ExerciseProgress:
    """The drive-by-wire exercise's progress: every objective passed (or the last not), each
    resting on run 3 of the exercise's attempt, driven by ben."""
    lab = next(lab for lab in load_labs() if lab.id == LAB)
    exercise = lab.exercise(EXERCISE)
    evidence = {
        "attempt": "a1b2c3",
        "person": "ben",
        "run": 3,
        "driver": "keys (ben)",
        "maze": "Unity maze",
        "profile": "unity",
        "ended": "exit",
        "metrics": {"exit_time": 41.5, "distance": 12.25, "collisions": 0},
        "record": record,
        "record_sha256": file_sha256(record) if record else None,
        "sensors": ["distance:1:right", "distance:2:front"],
        "hand_blocks": 1,
    }
    states = [
        ObjectiveState(o.kind, o.text, True, "done", dict(evidence)) for o in exercise.objectives
    ]
    if not passed:
        states[-1] = ObjectiveState(states[-1].kind, states[-1].text, False, "not yet", {})
    return ExerciseProgress(LAB, EXERCISE, states)


def save_student(store: Store, student: str, passed: bool = True, record: str = "") -> None:
    store.progress.set_place(student, LAB, EXERCISE)
    store.progress.save(student, LAB, EXERCISE, json.loads(progress(passed, record).to_json()))


WEB_LAB, WALL_MAIN = "web-simulator", "wall-main"
LONG_EXERCISE = ("unity-simulator", "reading-wall-following")


def wall_run(person: str, program: str, digest: str, attempt: str, run: int = 4) -> dict:
    """The evidence of a run of ``program`` on the Web maze, as the workbench now saves it:
    the sensors the run used, the program's name and digest, and its measures in pixels."""
    return {
        "attempt": attempt,
        "run": run,
        "driver": f"VIPLE program {program}",
        "person": person,
        "program_sha256": digest,
        "program_name": program,
        "sensors": ["distance:1:right", "touch:2:front"],
        "maze": "Web Simulator lab maze",
        "maze_digest": "f" * 64,
        "profile": "web",
        "ended": "exit",
        "metrics": {
            "reached_exit": True,
            "exit_time": 61.25,
            "sim_time": 61.25,
            "distance": 4245.42,
            "distance_cells": 60.65,
            "turn_degrees": 1980.0,
            "turns": 22,
            "collisions": 1,
            "efficiency": 0.4,
            "touches": 9,
        },
        "record": "",
        "record_sha256": None,
    }


def wall_main(
    person: str,
    program: str = "wall.viple",
    digest: str = "ab" * 32,
    attempt: str = "att-1",
    sensors_program: tuple[str, str] | None = None,
) -> ExerciseProgress:
    """web-simulator/wall-main done with ``program``: the sensors objective on one run (of
    ``sensors_program`` (name, digest) when given: the evidence then mixes programs), the exit
    on another, the questions right with their tries and none waiting."""
    sensor_name, sensor_digest = sensors_program or (program, digest)
    states = [
        ObjectiveState("sensors", "distance 1 right and touch 2 front", True,
                       "run 3 used distance:1:right, touch:2:front",
                       wall_run(person, sensor_name, sensor_digest, attempt, 3)),
        ObjectiveState("exit", "your program got out of the Web maze", True,
                       "run 4 got out", wall_run(person, program, digest, attempt)),
        ObjectiveState("questions", "questions answered", True, "all 2 answered correctly",
                       {"correct": 2, "of": 2, "tries": {"base": 1, "margin": 3},
                        "waiting": []}),
    ]  # fmt: skip
    return ExerciseProgress(WEB_LAB, WALL_MAIN, states)


def save_progress(store: Store, student: str, progress: ExerciseProgress) -> None:
    """``student`` at ``progress``'s exercise, with that progress saved."""
    store.progress.set_place(student, progress.lab, progress.exercise)
    store.progress.save(student, progress.lab, progress.exercise, json.loads(progress.to_json()))
