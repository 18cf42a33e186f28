"""The store's behaviour, the same on both databases: the SQLite file in the data folder and a
PostgreSQL database (a real server the test session starts, see tests/conftest.py)."""

from __future__ import annotations

import os
import socket
import subprocess
import sys
import threading
import time
from datetime import UTC, datetime
from pathlib import Path

import pytest

from tests.integration.signoff_support import fields
from tests.waiting import wait_until
from workbench.labs.signoff.instructors import KdfParams, create_instructor
from workbench.labs.signoff.roster import RosterEntry, offered_roster
from workbench.labs.signoff.signing import sign_off
from workbench.labs.signoff.signoff_errors import (
    LockedOut,
    SignoffError,
    UnknownInstructor,
    WrongPassphrase,
)
from workbench.labs.signoff.verify import verify_log
from workbench.labs.store.store import (
    LogMissing,
    Store,
    StoreError,
    StoreUnavailable,
    read_signoffs,
)

FAST = KdfParams(n=2**10, r=8, p=1)
PASS = "correct horse battery"
T0 = datetime(2026, 3, 2, 14, 5, 9, tzinfo=UTC)
ROOT = Path(__file__).resolve().parents[2]


class Where:
    """One store's place: its data folder and, for PostgreSQL, its database URL."""

    def __init__(self, data_dir: Path, db: str | None):
        self.data_dir = data_dir
        self.db = db

    def open(self) -> Store:
        return Store.open(self.data_dir, db=self.db)

    def raw(self, sql: str, params: tuple = ()) -> None:
        """Change the database behind the workbench's back (as someone with access could)."""
        with self.open() as store, store.backend.write() as tx:
            tx.execute(sql, params)

    def add_instructor(self, name: str = "Dr Chen") -> None:
        with self.open() as store:
            create_instructor(self.data_dir, name, PASS, kdf=FAST, store=store)

    def roster(self) -> dict[str, RosterEntry]:
        with self.open() as store:
            return offered_roster(store)


@pytest.fixture(params=["sqlite", "postgresql"])
def where(request, tmp_path: Path) -> Where:
    db = request.getfixturevalue("pg_url") if request.param == "postgresql" else None
    return Where(tmp_path / "data", db)


def test_progress_places_and_drivers_are_saved_replaced_and_read_back(where):
    with where.open() as s:
        assert s.progress.save("alice", "web", "ex1", {"objectives": {"keys": True}}, now=T0)
        s.progress.save("alice", "web", "ex1", {"objectives": {"keys": True, "maze": False}})
        s.progress.save("alice", "unity", "ex2", {"answers": [1]})
        s.progress.set_place("alice", "web", "ex1")
        s.progress.set_place("alice", "unity", "ex2")
        s.progress.set_driver("alice", "bob", "web", "ex1", "alice")
        s.progress.set_driver("alice", "bob", "web", "ex1", "bob")
        with pytest.raises(ValueError):
            s.progress.save("alice", "web", "ex1", {"t": float("inf")})
    with where.open() as s:  # another process (or server) opening the same store
        assert s.progress.of("alice", "web") == {
            ("web", "ex1"): {"objectives": {"keys": True, "maze": False}}
        }
        assert len(s.progress.of("alice")) == 2 and s.progress.of("nobody") == {}
        assert s.progress.place("alice") == ("unity", "ex2") and s.progress.place("bob") is None
        assert s.progress.drivers("alice", "bob") == {("web", "ex1"): "bob"}
        assert s.pending == 0 and s.available


def test_schema_steps_are_numbered_and_recorded_once(where):
    with where.open() as s:
        steps = s.migrations()
        version = s.schema_version()
    with where.open() as s:
        assert s.migrations() == steps  # opening again applies nothing
    expected = [(1, "tables"), (2, "sign-off chain")]
    if where.db:
        expected.append((3, "instructors' roster"))
    expected.append((4, "sign-off queue"))
    expected.append((5, "progress evidence"))
    expected.append((6, "workspace files"))
    assert steps == expected and version == expected[-1][0]


def old_progress(evidence: dict) -> dict:
    """An exercise's progress as workbenches before step 4 saved it: a pass of each kind."""
    return {
        "lab": "unity-simulator", "exercise": "drive-by-wire", "passed": True,
        "answers": {"tcp-port": "1350"},
        "objectives": [
            {"kind": "keys", "text": "drove", "passed": True, "reason": "used w",
             "evidence": evidence},
            {"kind": "maze-edited", "text": "edited", "passed": True,
             "reason": "the maze was edited and is valid", "evidence": {"maze_digest": "ab"}},
            {"kind": "questions", "text": "answered", "passed": True,
             "reason": "all 1 answered correctly", "evidence": {"correct": 1, "of": 1}},
        ],
    }  # fmt: skip


def test_passes_saved_without_their_work_need_redoing_after_the_upgrade(where):
    with where.open() as s:
        s.progress.save("ana", "unity-simulator", "drive-by-wire", old_progress({}))
        kept = old_progress({"attempt": "5eed", "keys_used": ["w"]})
        s.progress.save("ben", "unity-simulator", "drive-by-wire", kept)
    # as a store before step 5 was: the step not applied, the older schema version
    with where.open() as store, store.backend.write() as tx:
        tx.execute("DELETE FROM schema_migrations WHERE version = 5")
        tx.execute("UPDATE meta SET value = ? WHERE key = 'schema_version'", ("4",))
    with where.open() as s:
        assert (5, "progress evidence") in s.migrations()
        ana = s.progress.of("ana")[("unity-simulator", "drive-by-wire")]
        ben = s.progress.of("ben")[("unity-simulator", "drive-by-wire")]
    keys, edited, answered = ana["objectives"]
    assert (keys["passed"], keys["redo"], keys["reason"].startswith("needs redoing")) == (
        False, True, True)  # fmt: skip
    assert (edited["passed"], edited["redo"]) == (False, True)
    assert answered["passed"] is True and "redo" not in answered  # the answers are kept
    assert ana["passed"] is False and ana["answers"] == {"tcp-port": "1350"}
    # a pass with the evidence of its work is left as it was
    assert ben["objectives"][0] == kept["objectives"][0]


def test_a_store_written_by_a_newer_workbench_is_refused(where):
    where.open().close()
    where.raw("UPDATE meta SET value = '99' WHERE key = 'schema_version'")
    with pytest.raises(StoreError, match=r"newer workbench \(schema 99"):
        where.open()


def test_signoffs_form_one_log_that_verifies_and_reads_back_the_same(where):
    where.add_instructor()
    roster = where.roster()
    assert list(roster) == ["Dr Chen"]
    with where.open() as s:
        for student in ("alice", "carol", "dave"):
            sign_off(s, "Dr Chen", PASS, fields(student=student, driver=student))
        stored = s.signoffs.of()
        assert [r.student for r in s.signoffs.of(student="bob")] == ["alice", "carol", "dave"]
    assert [r.seq for r in stored] == [1, 2, 3]
    read = read_signoffs(where.data_dir, where.db)
    assert read == stored
    log = verify_log(read, roster)
    assert log.ok and log.head.seq == 3


def test_a_record_edited_in_the_database_fails_verify(where):
    where.add_instructor()
    with where.open() as s:
        sign_off(s, "Dr Chen", PASS, fields())
    where.raw("UPDATE signoffs SET note = 'great work'")
    [verdict] = verify_log(read_signoffs(where.data_dir, where.db), where.roster()).verdicts
    assert any("signature does not match" in p for p in verdict.problems)


def test_a_sequence_number_is_taken_once(where):
    where.add_instructor()
    with where.open() as s:
        sign_off(s, "Dr Chen", PASS, fields())
    columns = (
        "student, partner, driver, lab, exercise, instructor, signed_at, note, override, "
        "run_record, evidence_digest, metrics, signature, seq"
    )
    with pytest.raises(StoreError, match=r"(?i)unique"):
        where.raw(f"INSERT INTO signoffs ({columns}) SELECT {columns} FROM signoffs")


def test_the_lockout_counts_across_a_reopen(where):
    where.add_instructor()
    for _ in range(4):
        with where.open() as s, pytest.raises(WrongPassphrase):
            sign_off(s, "Dr Chen", "wrong wrong wrong", fields(), clock=lambda: T0)
    with where.open() as s:
        with pytest.raises(LockedOut, match="60 s more"):
            sign_off(s, "Dr Chen", "wrong wrong wrong", fields(), clock=lambda: T0)
        events = [e.event for e in s.signoffs.events("Dr Chen")]
        assert events == ["wrong-passphrase"] * 5 + ["locked"]


def test_two_threads_write_at_the_same_time(where):
    where.open().close()
    errors: list[BaseException] = []

    def writer(who: str) -> None:
        try:
            with where.open() as s:
                for i in range(30):
                    s.progress.save(who, "lab", f"ex{i}", {"i": i})
                    s.signoffs.log_event(who, "tick", str(i), T0)
        except BaseException as exc:
            errors.append(exc)

    threads = [threading.Thread(target=writer, args=(w,)) for w in ("alice", "bob")]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert errors == []
    with where.open() as s:
        assert len(s.progress.of("alice")) == 30 and len(s.progress.of("bob")) == 30
        assert len(s.signoffs.events()) == 60


SIGNER = """
import os, sys, time
from workbench.labs.signoff.signing import sign_off
from workbench.labs.signoff.signoff_record import RecordFields
from workbench.labs.store.store import Store
data_dir, db, who, ready = sys.argv[1], sys.argv[2] or None, sys.argv[3], sys.argv[4]
fields = RecordFields(student=who, lab="lab", exercise="ex", objectives_passed=True)
with Store.open(data_dir, db=db) as store:
    open(os.path.join(ready, who), "w").close()  # ready; both begin once both are
    while len(os.listdir(ready)) < 2:
        time.sleep(0.001)
    for i in range(10):
        sign_off(store, "Dr Chen", "correct horse battery", fields)
"""


def test_two_processes_signing_at_once_make_one_log(where, tmp_path):
    """Two servers' apps sign off at the same moment: one log, no number taken twice."""
    where.add_instructor()
    ready = tmp_path / "ready"  # each signer says it is ready here, and waits for the other
    ready.mkdir()
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    args = [str(where.data_dir), where.db or ""]
    procs = [
        subprocess.Popen([sys.executable, "-c", SIGNER, *args, who, str(ready)], env=env)
        for who in ("alice", "bob")
    ]
    assert [p.wait(timeout=120) for p in procs] == [0, 0]
    rows = read_signoffs(where.data_dir, where.db)
    assert [r.seq for r in rows] == list(range(1, 21))
    assert sorted(r.student for r in rows) == ["alice"] * 10 + ["bob"] * 10
    log = verify_log(rows, where.roster())
    assert log.ok, (log.breaks, [v.problems for v in log.verdicts if not v.ok])


# PostgreSQL only


def test_a_course_database_holds_the_roster_and_the_keys(pg_url, tmp_path):
    """An instructor added on one server signs on another: the key travels in the database,
    encrypted, and no file is written in either data folder."""
    one, two = Where(tmp_path / "one", pg_url), Where(tmp_path / "two", pg_url)
    one.add_instructor("Dr Chen")
    assert not (tmp_path / "one" / "instructors").exists()
    assert not (tmp_path / "one" / "roster.json").exists()
    with two.open() as s:
        assert list(offered_roster(s)) == ["Dr Chen"]
        assert '"encrypted_private_key"' in (s.instructors.key_file("Dr Chen") or "")
        sign_off(s, "Dr Chen", PASS, fields())
        with pytest.raises(WrongPassphrase):
            sign_off(s, "Dr Chen", "not the passphrase", fields())
        with pytest.raises(UnknownInstructor, match="no key for instructor Dr Lee"):
            sign_off(s, "Dr Lee", PASS, fields())
    with pytest.raises(SignoffError, match="already in the roster"):
        two.add_instructor("Dr Chen")


def test_reading_an_empty_database_finds_no_log_and_creates_nothing(pg_url, tmp_path):
    with pytest.raises(LogMissing, match="no meta table"):
        read_signoffs(tmp_path, pg_url)
    with pytest.raises(LogMissing):
        read_signoffs(tmp_path, pg_url)  # still nothing: reading made no table


def test_a_database_that_is_not_the_workbenchs_is_refused(pg_url, tmp_path):
    import psycopg

    with psycopg.connect(pg_url, autocommit=True) as conn:
        conn.execute("CREATE TABLE customers (id int)")
    with pytest.raises(StoreError, match="not a workbench database"):
        Store.open(tmp_path, db=pg_url)


def test_a_database_host_lost_without_a_word_is_noticed_within_seconds(pg_url, tmp_path):
    """The connection's socket gives up on a write the host does not acknowledge after 10 s
    (the kernel's TCP user timeout) and probes an idle link with keepalives, instead of the
    system's TCP retries (about 15 minutes) during which a save would wait; a URL that sets
    its own value keeps it."""

    def socket_settings(url: str) -> tuple[int, int, int]:
        with Store.open(tmp_path, db=url) as store:
            store.progress.save("ana", "lab", "exercise", "{}")
            sock = socket.socket(fileno=os.dup(store.backend.conn.fileno()))
            with sock:
                return (
                    sock.getsockopt(socket.IPPROTO_TCP, socket.TCP_USER_TIMEOUT),
                    sock.getsockopt(socket.SOL_SOCKET, socket.SO_KEEPALIVE),
                    sock.getsockopt(socket.IPPROTO_TCP, socket.TCP_KEEPIDLE),
                )

    assert socket_settings(pg_url) == (10_000, 1, 30)
    assert socket_settings(pg_url + "?tcp_user_timeout=2500")[0] == 2500


def test_an_unreachable_server_is_named_without_its_password(tmp_path):
    from tests.pgserver import free_port

    url = f"postgresql://teacher:s3cret@127.0.0.1:{free_port()}/course"
    with pytest.raises(StoreError, match="cannot be reached") as caught:
        Store.open(tmp_path, db=url)
    assert "s3cret" not in str(caught.value) and "teacher:***@127.0.0.1" in str(caught.value)


def test_the_database_stopped_and_restarted_under_a_writer_loses_nothing(
    pg_server, pg_url, tmp_path
):
    """A student keeps working while the course database restarts: every save reports
    whether it reached the database, what did not is kept and written once it is back, and
    afterwards the database holds every save, the newest of each exercise."""
    store = Store.open(tmp_path, db=pg_url)
    outcome: dict[int, bool] = {}
    stop = threading.Event()

    def writer() -> None:
        i = 0
        while not stop.is_set():
            outcome[i] = store.progress.save("alice", "lab", f"ex{i % 25}", {"i": i})
            i += 1
            time.sleep(0.01)

    thread = threading.Thread(target=writer)
    thread.start()
    try:
        wait_until(lambda: sum(outcome.values()) >= 20, "twenty saves in the database")
        pg_server.stop()
        down_from = len(outcome)
        # saves made while the server is down
        wait_until(lambda: len(outcome) >= down_from + 50, "fifty saves with the server down")
        assert not any(outcome[i] for i in range(down_from + 5, len(outcome)))  # pending
        assert store.pending > 0 and not store.available
        with pytest.raises(StoreError, match=r"cannot be reached|went away"):
            store.signoffs.of()  # reads say so; they never wait on a dead server
    finally:
        pg_server.start()
    # what a front end does now and then, in a thread of its own: flush, while the student
    # keeps saving; once the database answers, saves reach it again at once
    back_from = len(outcome)
    wait_until(store.flush, "the pending saves written", every=0.05)
    flushed_at = len(outcome)
    wait_until(lambda: len(outcome) >= flushed_at + 20, "twenty saves after the flush")
    stop.set()
    thread.join()
    assert outcome[len(outcome) - 1] and len(outcome) > back_from
    store.flush()
    assert store.pending == 0
    last = len(outcome) - 1
    with Store.open(tmp_path, db=pg_url) as fresh:
        saved = fresh.progress.of("alice")
    newest = {f"ex{i % 25}": i for i in range(last + 1)}
    assert {ex: p["i"] for (_, ex), p in saved.items()} == newest
    store.close()


def test_a_store_opened_while_the_server_is_down_catches_up_when_it_is_back(
    pg_server, pg_url, tmp_path
):
    Store.open(tmp_path, db=pg_url).close()
    pg_server.stop()
    try:
        store = Store.open(tmp_path, db=pg_url, offline_ok=True)
        assert store.progress.save("alice", "lab", "ex1", {"i": 1}) is False
        assert store.progress.set_place("alice", "lab", "ex1") is False
        assert store.pending == 2 and not store.available
        with pytest.raises(StoreError, match="cannot be reached"):
            Store.open(tmp_path, db=pg_url)  # without offline_ok it says so at once
    finally:
        pg_server.start()
    wait_until(
        store.flush, "the pending saves written", every=0.05
    )  # once past the pause between tries
    with Store.open(tmp_path, db=pg_url) as fresh:
        assert fresh.progress.of("alice") == {("lab", "ex1"): {"i": 1}}
        assert fresh.progress.place("alice") == ("lab", "ex1")
    store.close()


@pytest.mark.parametrize("how", ["stopped", "locked"])
def test_every_call_to_a_database_that_hangs_is_given_up_and_the_write_kept(
    pg_server, pg_url, tmp_path, monkeypatch, how
):
    """A server stopped (SIGSTOP: its kernel still acknowledges, so no TCP timeout fires) or
    a table locked by another connection: a save is kept pending, a read and a sign-off fail
    as "unavailable", each within the deadline, and the kept save is written afterwards."""
    import psycopg

    monkeypatch.setenv("WORKBENCH_DB_TIMEOUT", "1")  # server side 1 s; this side 1 s more
    store = Store.open(tmp_path, db=pg_url)
    create_instructor(tmp_path, "Dr Chen", PASS, kdf=FAST, store=store)
    store.progress.save("ana", "lab", "ex", {"n": 1})
    pids: list[int] = []
    locker = None
    if how == "stopped":
        pids = pg_server.freeze()
    else:
        locker = psycopg.connect(pg_url)
        for table in ("progress", "signoffs"):
            locker.execute(f"LOCK TABLE {table} IN ACCESS EXCLUSIVE MODE")
    safety = threading.Timer(30, pg_server.thaw, (pids,))  # old code must not hang the tests
    safety.start()
    try:
        for call in (
            lambda: store.progress.save("ana", "lab", "ex", {"n": 2}),
            lambda: store.progress.of("ana"),
            lambda: sign_off(store, "Dr Chen", PASS, fields()),
        ):
            began = time.monotonic()
            try:
                assert call() is False  # the save: kept pending
            except StoreUnavailable as exc:
                assert "did not answer within 1 s" in str(exc) or "cannot be reached" in str(exc)
            assert time.monotonic() - began < 8
        assert store.pending == 1
    finally:
        safety.cancel()
        pg_server.thaw(pids)
        if locker is not None:
            locker.close()
    deadline = time.monotonic() + 20
    while not store.flush() and time.monotonic() < deadline:
        time.sleep(0.2)
    assert store.progress.of("ana")[("lab", "ex")] == {"n": 2}
    store.close()
