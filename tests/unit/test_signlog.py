"""The sign-off log as a chain: whatever is done to its records, with the head the instructor
kept, checking finds it; untouched, it verifies."""

from __future__ import annotations

from dataclasses import replace

import pytest
from cryptography.hazmat.primitives.asymmetric.ed25519 import Ed25519PrivateKey
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from workbench.labs.signlog import EMPTY_HEAD, GENESIS, Head, LogError, entry_hash, next_place
from workbench.labs.signoff.instructors import Instructor
from workbench.labs.signoff.roster import RosterEntry
from workbench.labs.signoff.signoff_record import Evidence, SignoffRecord
from workbench.labs.signoff.verify import verify_log
from workbench.labs.store.store import StoredSignoff

CHEN = Instructor("Dr Chen", Ed25519PrivateKey.generate())
ROGUE = Instructor("Dr Chen", Ed25519PrivateKey.generate())  # same name, another key
ROSTER = {"Dr Chen": RosterEntry("Dr Chen", CHEN.public_key_b64(), "")}


def record(n: int, student: str = "") -> SignoffRecord:
    return SignoffRecord(
        student=student or f"student{n}",
        partner="",
        driver="",
        lab="web-simulator",
        exercise=f"ex{n}",
        instructor="Dr Chen",
        signed_at=f"2026-03-02T10:{n:02d}:00Z",
        note="",
        override=False,
        evidence=Evidence("", "sha256:" + "ab" * 32, {"n": n}),
    )


def stored(rec: SignoffRecord, signer: Instructor, row_id: int) -> StoredSignoff:
    """A record signed at its place and stored as the database stores it."""
    signature = signer.sign(rec.canonical())
    columns = rec.columns(signature)
    return StoredSignoff(
        id=row_id,
        **columns,
        seq=rec.seq,
        prev_hash=rec.prev,
        entry_hash=entry_hash(rec.seq or 0, rec.prev, rec.canonical(), signature),
    )


def append(rows: list[StoredSignoff], rec: SignoffRecord, signer=CHEN) -> None:
    prev = rows[-1].entry_hash if rows else GENESIS
    seq = (rows[-1].seq or 0) + 1 if rows else 1
    rows.append(stored(replace(rec, seq=seq, prev=prev), signer, len(rows) + 1))


def signed_log(n: int) -> list[StoredSignoff]:
    rows: list[StoredSignoff] = []
    for i in range(1, n + 1):
        append(rows, record(i))
    return rows


LOG = signed_log(5)
HEAD = verify_log(LOG, ROSTER).head


def relinked(rows: list[StoredSignoff]) -> list[StoredSignoff]:
    """What someone who can write the database but holds no key does after changing records:
    renumber them and recompute every link and hash, which are not secret."""
    out: list[StoredSignoff] = []
    prev = GENESIS
    for seq, row in enumerate(rows, 1):
        row = replace(row, id=seq, seq=seq, prev_hash=prev)
        prev = entry_hash(seq, prev, row.signed_bytes(), row.signature)
        out.append(replace(row, entry_hash=prev))
    return out


def test_an_untouched_log_verifies_and_its_head_is_the_last_record():
    log = verify_log(LOG, ROSTER)
    assert log.ok and [v.problems for v in log.verdicts] == [()] * 5
    assert log.head == Head(5, LOG[-1].entry_hash)
    assert verify_log(LOG, ROSTER, kept=HEAD).ok
    assert verify_log(LOG, ROSTER, kept=verify_log(LOG[:2], ROSTER).head).ok  # it grew
    assert verify_log([], ROSTER).head == EMPTY_HEAD and verify_log([], ROSTER).ok


def test_a_deleted_record_breaks_the_chain_where_it_was():
    log = verify_log(LOG[:2] + LOG[3:], ROSTER)
    assert not log.ok
    assert log.breaks == ("the log breaks before sequence 4: record(s) 3 are missing (deleted)",)
    [problem] = log.verdicts[2].problems
    assert "does not follow the record before it" in problem
    assert [v.ok for v in log.verdicts] == [True, True, False, True]


def test_the_last_records_deleted_are_found_with_the_kept_head_only():
    assert verify_log(LOG[:3], ROSTER).ok  # nothing in the log itself shows it
    log = verify_log(LOG[:3], ROSTER, kept=HEAD)
    assert log.breaks == (
        "the log ends at sequence 3 but the kept head is at 5: records were removed from the "
        "end, or the database was rolled back to an older copy",
    )
    assert not verify_log([], ROSTER, kept=HEAD).ok


def test_a_log_rewritten_from_the_kept_head_on_is_found():
    other: list[StoredSignoff] = list(LOG[:2])  # the same start, then other records
    for i in range(3, 7):
        append(other, record(i, "zoe"))
    log = verify_log(other, ROSTER, kept=HEAD)
    assert log.breaks and "is not the one the kept head 5:" in log.breaks[0]
    assert [v.ok for v in log.verdicts] == [True] * 6


def test_a_duplicated_record_is_found_even_relinked():
    copied = verify_log([*LOG, LOG[1]], ROSTER)
    assert "sequence number 2 appears again" in copied.verdicts[5].problems[0]
    log = verify_log(relinked([*LOG, LOG[1]]), ROSTER)
    problems = log.verdicts[5].problems
    assert any("signature does not match" in p for p in problems)
    assert any("copy of the record with id 2" in p for p in problems)


def test_reordered_records_fail_their_signatures():
    swapped = [LOG[0], LOG[2], LOG[1], LOG[3], LOG[4]]
    log = verify_log(relinked(swapped), ROSTER)
    # every record from the swap on was signed at another place in the log
    assert [v.ok for v in log.verdicts] == [True, False, False, False, False]
    assert all("signature does not match" in v.problems[0] for v in log.verdicts[1:])


def test_an_inserted_record_signed_with_another_key_fails():
    forged: list[StoredSignoff] = list(LOG[:2])
    append(forged, record(9, "mallory"), signer=ROGUE)
    log = verify_log(relinked(forged + LOG[2:]), ROSTER)
    assert "signature does not match" in log.verdicts[2].problems[0]
    assert not log.verdicts[3].ok  # the genuine record after it lost its place


def test_a_legacy_record_cannot_be_replayed_after_chained_ones():
    legacy = stored(record(1), CHEN, 1)  # signed without a place in the log
    legacy = replace(legacy, legacy=True, seq=1, prev_hash=GENESIS)
    legacy = replace(
        legacy, entry_hash=entry_hash(1, GENESIS, legacy.signed_bytes(), legacy.signature)
    )
    rows = [legacy]
    append(rows, record(2))
    log = verify_log(rows, ROSTER)
    assert log.ok and log.legacy == 1
    assert "legacy record" in log.verdicts[0].notes[0]
    replayed = relinked([*rows, replace(legacy, legacy=True)])
    assert "legacy records can only come first" in " ".join(
        verify_log(replayed, ROSTER).verdicts[2].problems
    )


def test_a_record_by_a_key_or_a_name_not_in_the_trusted_roster_fails():
    rows = list(LOG[:1])
    lookalike = replace(record(2), instructor="Dr Сhen")  # a Cyrillic С
    append(rows, lookalike, signer=Instructor("Dr Сhen", ROGUE.private_key))
    append(rows, record(3), signer=ROGUE)
    local = {"Dr Chen": RosterEntry("Dr Chen", ROGUE.public_key_b64(), "")}
    log = verify_log(rows, ROSTER, local=local)
    assert log.verdicts[1].problems == ("instructor 'Dr Сhen' is not in the trusted roster",)
    assert "re-keyed in the data folder" in log.verdicts[2].problems[0]


def test_a_look_alike_student_name_in_a_signed_record_fails():
    rows: list[StoredSignoff] = []
    append(rows, record(1, "аlice"))  # a Cyrillic а, signed by the real key
    [problem] = verify_log(rows, ROSTER).verdicts[0].problems
    assert "mixes letters of different scripts (Cyrillic, Latin)" in problem


FIELDS = ("student", "note", "signed_at", "exercise", "instructor", "evidence_digest", "metrics")


@st.composite
def mutations(draw) -> tuple[str, list[StoredSignoff]]:
    n = len(LOG)
    kind = draw(st.sampled_from(["delete", "duplicate", "swap", "insert", "edit", "seq"]))
    rows = list(LOG)
    i = draw(st.integers(0, n - 1))
    if kind == "delete":
        del rows[i]
    elif kind == "duplicate":
        rows.insert(draw(st.integers(0, n)), LOG[i])
    elif kind == "swap":
        j = draw(st.integers(0, n - 1).filter(lambda j: j != i))
        rows[i], rows[j] = rows[j], rows[i]
    elif kind == "insert":
        fake: list[StoredSignoff] = []
        append(fake, record(draw(st.integers(0, 59)), "mallory"), signer=ROGUE)
        rows.insert(draw(st.integers(0, n)), fake[0])
    elif kind == "edit":
        name = draw(st.sampled_from(FIELDS))
        value = draw(st.text(min_size=1, max_size=8))
        if name == "metrics":
            value = '{"n":' + str(draw(st.integers(-5, 5))) + "}"
        rows[i] = replace(rows[i], **{name: value})
    else:
        rows[i] = replace(rows[i], seq=draw(st.integers(0, 9)))
    if draw(st.booleans()):
        rows = relinked(rows)
    return kind, rows


@settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(mutations())
def test_any_single_change_to_the_log_is_found_with_the_kept_head(case):
    kind, rows = case
    same = [(r.seq, r.prev_hash, r.entry_hash, r.signature, r.signed_bytes()) for r in rows] == [
        (r.seq, r.prev_hash, r.entry_hash, r.signature, r.signed_bytes()) for r in LOG
    ]
    log = verify_log(rows, ROSTER, kept=HEAD)
    assert log.ok == same, (kind, log.breaks, [v.problems for v in log.verdicts])


@given(st.text(max_size=120))
def test_a_kept_head_is_read_or_refused_with_the_reason(text):
    try:
        head = Head.parse(text)
    except LogError as exc:
        assert "is not SEQ:HASH" in str(exc)
    else:
        assert Head.parse(str(head)) == head


def test_heads_print_and_parse_as_seq_colon_hash():
    head = Head(12, "sha256:" + "0f" * 32)
    assert str(head) == "12:" + "0f" * 32
    assert Head.parse("12:sha256:" + "0F" * 32) == head
    for bad in ("12", "x:" + "0" * 64, "12:" + "0" * 63, "-1:" + "0" * 64):
        with pytest.raises(LogError, match="is not SEQ:HASH"):
            Head.parse(bad)


row_text = st.text(max_size=30)


@st.composite
def hostile_rows(draw) -> StoredSignoff:
    """A row as anyone who can write the database might leave it."""
    genuine = draw(st.sampled_from(LOG))
    metrics = draw(
        st.sampled_from(['{"n":1}', "NaN", '{"n":1e999}', "[" * 5000 + "]" * 5000, "9" * 5000, "{"])
        | row_text
    )
    return replace(
        genuine,
        student=draw(row_text | st.just(genuine.student)),
        instructor=draw(st.sampled_from(["Dr Chen", "Dr Сhen", ""]) | row_text),
        metrics=metrics,
        signature=draw(st.sampled_from([genuine.signature, "", "!!", "AAAA"]) | row_text),
        seq=draw(st.none() | st.integers(-(2**63), 2**63 - 1)),
        prev_hash=draw(st.sampled_from([genuine.prev_hash, GENESIS, ""]) | row_text),
        entry_hash=draw(st.sampled_from([genuine.entry_hash, ""]) | row_text),
        legacy=draw(st.booleans()),
    )


@settings(max_examples=200, deadline=None)
@given(st.lists(hostile_rows(), max_size=6))
def test_whatever_the_rows_hold_checking_gives_a_verdict(rows):
    log = verify_log(rows, ROSTER, kept=HEAD)
    assert len(log.verdicts) == len(rows)
    assert not log.ok  # none of these is the kept log


def test_the_next_place_follows_the_run_of_numbers_the_log_grew_by():
    h = ["sha256:" + c * 64 for c in "abcd"]
    assert next_place([]) == (1, GENESIS)
    assert next_place([(1, h[0]), (2, h[1])]) == (3, h[1])
    # a planted far-off number, or one below 1, is stepped over
    assert next_place([(-5, h[3]), (1, h[0]), (2, h[1]), (999999999999999999, h[2])]) == (3, h[1])
    # records deleted from the start: the run starts at the first one left
    assert next_place([(4, h[0]), (5, h[1])]) == (6, h[1])
