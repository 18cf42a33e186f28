"""What the tests that drive a :class:`LabStation` share: a run started and stepped on the
test's own clock (60 steps a simulated second, no real time) until the station records it."""

from __future__ import annotations

from workbench.control.station import LabStation, RunEntry

#: simulated seconds a run may take before a test gives up on it (a bound on a failure only:
#: a run that ends stops the stepping at once)
RUN_LIMIT_S = 600


def run_once(station: LabStation, limit_s: int = RUN_LIMIT_S) -> RunEntry | None:
    """Start a run with what drives the station now and step it until it ends; the run, or
    None when it had not ended after ``limit_s`` simulated seconds."""
    station.start()
    before = len(station.runs)
    for _ in range(limit_s):
        station.step(60)
        if len(station.runs) > before:
            return station.runs[-1]
    return None


def run_to_exit(station: LabStation, limit_s: int = RUN_LIMIT_S) -> RunEntry:
    """:func:`run_once`, which must end with the robot out of the maze; the run."""
    run = run_once(station, limit_s)
    if run is None:
        driver = station.algorithm.name if station.algorithm else "the run"
        raise AssertionError(f"{driver} did not get out of {station.maze.name}")
    assert run.ended == "exit", run
    return run
