"""The file of writes the course database did not get: what it keeps, what is refused when read
back, and that a kept write never undoes what was saved after it."""

from __future__ import annotations

import json
from datetime import UTC, datetime

from workbench.labs.store.pending import PendingWrite, load_pending, pending_path, save_pending
from workbench.labs.store.store import Store

WHEN = datetime(2026, 3, 2, 10, 0, tzinfo=UTC)
LATER = datetime(2026, 3, 2, 11, 0, tzinfo=UTC)


def progress(student: str, answer: str, stamp: str = "2026-03-02T10:00:00Z") -> PendingWrite:
    text = json.dumps({"answers": {"q": answer}})
    return PendingWrite("progress", (student, "lab1", "ex1", text, stamp))


def test_the_file_is_per_student_and_reads_back_what_was_kept(tmp_path):
    ana, ben = pending_path(tmp_path, "ana"), pending_path(tmp_path, "ben")
    assert ana != ben and ana.parent == ben.parent == tmp_path / "pending"
    writes = [progress("ana", "1"), PendingWrite("place", ("ana", "lab1", "ex1", "t"))]
    save_pending(ana, "ana", writes)
    assert load_pending(ana, "ana") == (writes, [])
    save_pending(ana, "ana", [])
    assert not ana.exists()  # nothing pending, no file


def test_a_tampered_file_gives_only_the_students_own_well_formed_writes(tmp_path):
    path = pending_path(tmp_path, "ana")
    save_pending(path, "ana", [progress("ana", "1")])
    data = json.loads(path.read_text())
    data["writes"] += [
        {"kind": "progress", "values": ["ben", "lab1", "ex1", "{}", "t"]},
        {"kind": "DROP TABLE progress", "values": []},
        {"kind": "place", "values": ["ana", "lab1"]},
        {"kind": "progress", "values": ["ana", "lab1", "ex2", "[1]", "t"]},
        {"kind": "driver", "values": ["ana", "", "lab1", "ex1", 7, "t"]},
    ]
    path.write_text(json.dumps(data))
    writes, problems = load_pending(path, "ana")
    assert writes == [progress("ana", "1")]
    assert [p.split(": ", 1)[1] for p in problems] == [
        "write 2 left out: it is another student's",
        "write 3 left out: not a known kind of write",
        "write 4 left out: a place write needs 4 values (student, lab, exercise, updated_at)",
        "write 5 left out: its progress is not a JSON object",
        "write 6 left out: its values must be text",
    ]
    assert load_pending(path, "ben")[0] == []  # ana's file is not ben's
    path.write_text("not json")
    assert load_pending(path, "ana")[0] == []


def test_kept_writes_are_saved_but_never_over_a_newer_save(tmp_path):
    kept = pending_path(tmp_path, "ana")
    save_pending(
        kept,
        "ana",
        [progress("ana", "old", "2026-03-02T10:00:00Z"),
         PendingWrite("place", ("ana", "lab1", "ex9", "2026-03-02T10:00:00Z"))],
    )  # fmt: skip
    with Store.open(tmp_path / "data") as store:
        store.progress.save("ana", "lab1", "ex1", {"answers": {"q": "new"}}, now=LATER)
        assert store.keep_pending_in(kept, "ana") == []
        assert store.pending == 2
        assert store.flush()
        assert store.progress.of("ana")[("lab1", "ex1")] == {"answers": {"q": "new"}}
        # nothing newer: the kept one is saved
        assert store.progress.place("ana") == ("lab1", "ex9")
    assert not kept.exists()
