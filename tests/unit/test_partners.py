"""The partner a request names is not taken on its word (issue 37): the partner must be a
student of the class, the instructor confirms the pair, and a record that only names someone
never replaces a gradebook row of their own."""

from __future__ import annotations

import json

import pytest

from workbench.labs.checks import ExerciseProgress, ObjectiveState
from workbench.labs.classview import read_request
from workbench.labs.partners import PairNotConfirmed, partner_problem
from workbench.labs.signlog import Head
from workbench.labs.signoff.gradebook import gradebook_rows
from workbench.labs.store.store import Store, StoredSignoff


def signed(seq: int, student: str, partner: str, at: str) -> StoredSignoff:
    return StoredSignoff(
        seq, student, partner, student, "lab", "ex", "Dr Chen", at, "", False, "", "d", "{}",
        "sig", seq=seq,
    )  # fmt: skip


def test_a_record_naming_a_partner_never_replaces_their_own_row():
    rows = [
        signed(1, "ben", "", "2026-03-02T10:00:00Z"),  # ben's own sign-off
        signed(2, "ana", "ben", "2026-03-02T11:00:00Z"),  # later, ana names ben
    ]
    book = {r["student"]: r for r in gradebook_rows(rows, Head(2, "h"))}
    assert book["ben"]["signed_at"] == "2026-03-02T10:00:00Z" and book["ben"]["partner"] == ""
    assert book["ana"]["partner"] == "ben"
    # a partner's row of their own replaces one that only named them, as before
    rows = [
        signed(1, "ana", "ben", "2026-03-02T10:00:00Z"),
        signed(2, "ben", "", "2026-03-02T11:00:00Z"),
    ]
    book = {r["student"]: r for r in gradebook_rows(rows, Head(2, "h"))}
    assert book["ben"]["signed_at"] == "2026-03-02T11:00:00Z"


def test_a_partner_is_a_student_of_the_class_other_than_the_student():
    assert partner_problem("ana", "", {"ana"}) == ""
    assert partner_problem("ana", "ben", {"ana", "ben"}) == ""
    assert "not a student of this class" in partner_problem("ana", "zed", {"ana", "ben"})
    assert "names themself" in partner_problem("ana", "Ana", {"ana"})


def test_a_request_s_partner_is_on_the_sign_off_only_when_the_instructor_confirms(tmp_path):
    progress = ExerciseProgress(
        "lab", "ex", [ObjectiveState("keys", "drive", True, "done", {"person": "ana"})]
    )
    with Store.open(tmp_path / "data") as store:
        store.progress.set_place("ana", "lab", "ex")
        store.progress.save("ana", "lab", "ex", json.loads(progress.to_json()))
        entry = store.queue.request("ana", "zed", "ana", "lab", "ex").entry
        assert entry is not None
        request = read_request(store, entry, [])
        assert "zed is not a student of this class" in request.partner_problem
        with pytest.raises(PairNotConfirmed):
            request.fields()
        with pytest.raises(ValueError, match="not a student of this class"):
            request.fields(partner_agrees=True)
        assert request.fields(partner_agrees=False).partner == ""
        store.progress.set_place("zed", "lab", "ex")
        request = read_request(store, entry, [])
        assert request.partner_problem == ""
        assert request.fields(partner_agrees=True).partner == "zed"
