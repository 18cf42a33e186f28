"""A run's numbers do not depend on how fast it is shown: at every speed, and in single steps,
the app's station runs the same simulation steps as ``workbench run`` and stops at the exit."""

from __future__ import annotations

from pathlib import Path

import pytest

from workbench.control.headless import AlgorithmPilot, RunSpec, run
from workbench.control.station import LabStation
from workbench.sim.clock import SPEEDS
from workbench.sim.mazeio import load_maze

MAZE = "mazes/rank-wall-wins.txt"


def headless(record: str | None = None) -> dict:
    return run(RunSpec(MAZE, AlgorithmPilot("right-wall"), seed=3, record=record)).metrics


def ticks(path) -> list[str]:
    """A run record's ticks (its header and summary say how it was made)."""
    return [line for line in Path(path).read_text().splitlines() if not line.startswith('{"type"')]


def station_run(speed: float | None, single: int | None = None, record_dir=None) -> dict:
    station = LabStation.open(load_maze(MAZE), seed=3, record_dir=record_dir)
    station.select_algorithm("right-wall")
    station.apply_algorithm_preset()
    station.start()
    station.pacer.speed = speed
    for _ in range(100_000):
        if station.runs:
            break
        if single is not None:
            station.step(single)
        else:
            station.advance(0.05)  # a frame at 20 Hz: at max speed the budget decides the steps
    (entry,) = station.runs
    assert entry.ended == "exit"
    return entry.metrics.as_dict() | {"record": entry.record}


@pytest.mark.parametrize("speed", SPEEDS, ids=lambda s: f"{s}x" if s else "max")
def test_every_speed_gives_the_numbers_of_a_headless_run(speed):
    got, want = station_run(speed), headless()
    assert got["reached_exit"] and got["exit_time"] == want["exit_time"]
    for key in ("sim_time", "distance", "turn_degrees", "turns", "collisions"):
        assert got[key] == pytest.approx(want[key], abs=1e-9), key


@pytest.mark.parametrize("single", [1, 7, 60])
def test_single_steps_stop_at_the_exit_too(single):
    got, want = station_run(1.0, single), headless()
    assert got["sim_time"] == pytest.approx(want["sim_time"])
    assert got["distance"] == pytest.approx(want["distance"])


def test_the_app_s_run_record_holds_the_ticks_of_the_headless_record(tmp_path):
    got = station_run(None, record_dir=str(tmp_path / "app"))
    headless(record=str(tmp_path / "headless.jsonl"))
    assert ticks(got["record"]) == ticks(tmp_path / "headless.jsonl")
