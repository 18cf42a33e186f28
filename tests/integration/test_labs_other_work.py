"""Doing the whole work of any bundled exercise, as a student would, never passes an objective
of another exercise: whether that other one was never set up, or was set up before."""

from __future__ import annotations

import tempfile
from pathlib import Path

from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from workbench.control.station import LabStation
from workbench.labs.behaviour import BehaviourJudge
from workbench.labs.progress import LabProgress

from .test_labs_completable import EXERCISES, LABS, complete

PAIRS = [(a, b) for a in EXERCISES for b in EXERCISES if a != b]


@settings(max_examples=12, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(pair=st.sampled_from(PAIRS), other_set_up_first=st.booleans())
def test_the_work_of_one_exercise_never_passes_another(pair, other_set_up_first):
    (lab_id, ex), (other_lab, other) = pair
    station = LabStation.open(ex.setup.maze.maze, ex.setup.profile, noise="off")
    progress = LabProgress("ana", "ben")
    progress.judge = BehaviourJudge(station.files, inline=True)  # a drawn machine judged at once
    if other_set_up_first:
        progress.set_up(station, LABS[other_lab], other)
    progress.set_up(station, LABS[lab_id], ex)
    with tempfile.TemporaryDirectory() as folder:  # (hypothesis runs it many times)
        for question, text in complete(station, ex, Path(folder)).items():
            progress.answer((lab_id, ex.id), question, text)
        assert progress.check(lab_id, ex, station).passed  # the work was done, for its exercise
        checked = progress.check(other_lab, other, station)
    passed = {o.text for o in checked.objectives if o.passed}
    assert passed == set(), (lab_id, ex.id, other_lab, other.id, passed)
