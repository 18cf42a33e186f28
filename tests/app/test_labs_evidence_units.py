"""Under a passed objective the labs screen gives the run's figures with their units: the
time in seconds, the distance in the profile's unit and in blocks, the degrees turned."""

from __future__ import annotations

import re

from textual.pilot import Pilot

from .labs_support import evidence_lines, lab_app, open_exercise
from .support import run

READING = "unity-simulator/reading-wall-following"


def test_the_evidence_run_is_shown_with_units(tmp_path):
    app = lab_app(tmp_path / "data")

    async def body(pilot: Pilot) -> None:
        station = app.station
        screen = await open_exercise(pilot, READING)
        await pilot.press("a")  # the erobotic maze, on the Unity robot, right-wall chosen
        await pilot.pause()
        station.start()
        for _ in range(3000):
            if station.session.reached_exit:
                break
            station.step(30)
        assert station.session.reached_exit
        screen.show_snapshot(station.snapshot())
        await pilot.pause()
        line = next(line for line in evidence_lines(screen) if line.startswith("run "))
        joined = " ".join(" ".join(evidence_lines(screen)).split())
        figures = r"\d+\.\d s, \d+\.\d unit \(\d+\.\d blocks\), \d+ deg turned, \d+ collisions?"
        assert re.search(rf"\(algorithm right-wall\): {figures}", joined), line

    run(app, body)
