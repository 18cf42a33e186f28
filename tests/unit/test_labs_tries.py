"""Every try at a question is counted and saved; a lab file may cap them, after which a
question not answered right waits for the instructor."""

from __future__ import annotations

import re

import pytest

from workbench.control.station import LabStation
from workbench.labs.checks import evaluate
from workbench.labs.model import LabFileError, load_lab, load_labs
from workbench.labs.progress import LabProgress, evidence_words, read_saved
from workbench.labs.signoff.signoff_record import Evidence
from workbench.labs.store.store import Store

from .test_labs_model import folder, good_text, write  # noqa: F401  (folder: a fixture)

LAB = next(lab for lab in load_labs() if lab.id == "unity-simulator")
DRIVE = LAB.exercise("drive-by-wire")
KEY = (LAB.id, DRIVE.id)


def capped(folder, tries: str = "2", where: str = "question"):  # noqa: F811
    text = good_text()
    if where == "question":
        text = text.replace("        text: Which port?\n", f"        text: Which port?\n"
                            f"        max_tries: {tries}\n")  # fmt: skip
    else:
        text = text.replace("    signoff:", f"    max_tries: {tries}\n    signoff:")
    return load_lab(write(folder, text))


def test_every_try_is_counted_but_not_the_same_answer_twice():
    progress = LabProgress("ana")
    assert progress.answer(KEY, "tcp-port", "1351")
    assert not progress.answer(KEY, "tcp-port", "1351 ")  # the answer kept already
    assert not progress.answer(KEY, "tcp-port", "  ")  # nothing tried
    assert progress.answer(KEY, "tcp-port", "1350")
    assert progress.tries_of(KEY, "tcp-port") == 2
    station = LabStation.open(DRIVE.setup.maze.maze, "unity", noise="off")
    checked = progress.check(LAB.id, DRIVE, station)
    (questions,) = [o for o in checked.objectives if o.kind == "questions"]
    assert questions.evidence == {"correct": 1, "of": 1, "tries": {"tcp-port": 2}, "waiting": []}
    assert evidence_words(questions) == "1 of 1 right; tries: tcp-port 2"


def test_tries_are_saved_with_the_progress_and_read_back(tmp_path):
    progress = LabProgress("ana")
    for text in ("1", "2", "1350"):
        progress.answer(KEY, "tcp-port", text)
    station = LabStation.open(DRIVE.setup.maze.maze, "unity", noise="off")
    checked = progress.check(LAB.id, DRIVE, station)
    with Store.open(tmp_path / "data") as store:
        progress.save(store, checked)
        again = LabProgress("ana")
        again.take(read_saved(store, "ana"))
    assert again.tries[KEY] == {"tcp-port": 3}
    assert again.saved[KEY].tries == {"tcp-port": 3}
    assert not again.changed(checked)


def test_progress_saved_before_tries_were_kept_reads_as_none_tried():
    from workbench.labs.checks import ExerciseProgress

    old = {"lab": LAB.id, "exercise": DRIVE.id, "answers": {"tcp-port": "1350"},
           "objectives": []}  # fmt: skip
    assert ExerciseProgress.from_dict(old).tries == {}


def test_a_capped_question_takes_no_more_answers_and_waits_for_the_instructor(folder):  # noqa: F811
    lab = capped(folder, "2")
    ex = lab.exercises[0]
    (q,) = ex.questions
    assert q.max_tries == 2
    key = (lab.id, ex.id)
    progress = LabProgress("ana")
    assert progress.answer(key, "port", "1", q.max_tries)
    assert progress.answer(key, "port", "2", q.max_tries)
    assert not progress.can_answer(key, "port", q.max_tries)
    assert not progress.answer(key, "port", "1350", q.max_tries)  # no tries left
    station = LabStation.open(ex.setup.maze.maze, "unity", noise="off")
    checked = evaluate(lab.id, ex, station, progress.answers[key], progress.tries[key])
    (questions,) = [o for o in checked.objectives if o.kind == "questions"]
    assert (questions.passed, questions.reason) == (
        False,
        "no tries left, waiting for the instructor: port",
    )
    assert questions.evidence["waiting"] == ["port"]
    assert questions.evidence["tries"] == {"port": 2}
    # the sign-off's evidence keeps them
    (kept,) = [o for o in Evidence.of_progress(checked).metrics["objectives"]
               if o["kind"] == "questions"]  # fmt: skip
    assert kept["evidence"]["waiting"] == ["port"]


def test_a_right_answer_within_the_cap_does_not_wait(folder):  # noqa: F811
    lab = capped(folder, "1", where="exercise")
    ex = lab.exercises[0]
    (q,) = ex.questions
    assert q.max_tries == 1  # the exercise's cap is each question's
    key = (lab.id, ex.id)
    progress = LabProgress("ana")
    assert progress.answer(key, "port", "1350", q.max_tries)
    station = LabStation.open(ex.setup.maze.maze, "unity", noise="off")
    checked = evaluate(lab.id, ex, station, progress.answers[key], progress.tries[key])
    (questions,) = [o for o in checked.objectives if o.kind == "questions"]
    assert questions.passed and questions.evidence["waiting"] == []


@pytest.mark.parametrize("bad", ["0", "2.5", "yes", "1000"])
def test_a_wrong_max_tries_is_named_with_its_line_and_fix(folder, bad):  # noqa: F811
    with pytest.raises(LabFileError) as err:
        capped(folder, bad)
    assert re.search(
        r"small\.yaml:21:\d+: exercise 'drive': question 'port': max_tries: "
        rf"'{re.escape(bad)}' is not a whole number from 1 to 100 \(hint: write how many "
        r"answers a student may try, e.g. 'max_tries: 3'\)",
        str(err.value),
    ), err.value
