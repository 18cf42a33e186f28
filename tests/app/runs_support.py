"""What the runs screen's tests share: runs made on a station by algorithms and by a VIPLE
program file with a long name."""

from __future__ import annotations

import shutil
from pathlib import Path

from tests.stations import run_once
from workbench.control.station import LabStation
from workbench.program.choice import choose_program
from workbench.sim.mazefile import parse_maze
from workbench.sim.mazeio import load_maze

PROGRAMS = Path(__file__).resolve().parents[2] / "programs"
BEND = parse_maze(
    "---\nname: Bend\n---\n#######\n#S....#\n#####.#\n#E....#\n#######\n", source="bend.txt"
)


def run_algorithms(station: LabStation, *names: str) -> LabStation:
    for name in names:
        station.select_algorithm(name)
        station.apply_algorithm_preset()
        run_once(station, limit_s=200)
    return station


def run_program(station: LabStation, path) -> None:
    """Run the VIPLE program file at ``path`` from the start block until its run ends."""
    station.use_program(choose_program(station, str(path)))
    run_once(station, limit_s=400)


def runs_with_long_driver_names(tmp_path) -> LabStation:
    """A student's program with a long file name and an algorithm on the Web maze, then a run
    on Bend: the station is left on the Web maze."""
    program = tmp_path / "my-own-right-wall-follower-for-the-web-maze.viple"
    shutil.copy(PROGRAMS / "right-wall.viple", program)
    station = LabStation.open(
        load_maze("mazes/web.txt"), "web", noise="off", record_dir=str(tmp_path / "runs")
    )
    run_program(station, program)
    run_algorithms(station, "two-distance-local-best")
    station.load_maze(BEND)
    run_algorithms(station, "right-wall")
    station.load_maze(load_maze("mazes/web.txt"))
    assert [r.ended for r in station.runs] == ["exit"] * 3
    return station
