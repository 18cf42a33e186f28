"""What the console tests share: a class's saved progress in a store, and waiting for screens."""

from __future__ import annotations

import json
import time
from collections.abc import Callable
from pathlib import Path

from textual.pilot import Pilot

from workbench.labs.checks import ExerciseProgress, ObjectiveState
from workbench.labs.model import load_labs
from workbench.labs.store import Store
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
    store.set_place(student, LAB, EXERCISE)
    store.save_progress(student, LAB, EXERCISE, json.loads(progress(passed, record).to_json()))


async def until(pilot: Pilot, done: Callable[[], object], what: str, seconds: float = 10) -> None:
    """Let the app run until ``done()`` holds (the event the test waits for)."""
    deadline = time.monotonic() + seconds
    while not done():
        assert time.monotonic() < deadline, f"waited {seconds} s for {what}"
        await pilot.pause(0.05)
