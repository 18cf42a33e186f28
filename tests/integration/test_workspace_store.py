"""One workspace for the course: a served student's files kept in the store's workspace table
(the same on SQLite and PostgreSQL), brought into any server's workspace folder when a session
starts, sent as the app saves them, and used by ``signoff verify`` on any machine."""

from __future__ import annotations

import hashlib
import os
import threading
from dataclasses import replace
from pathlib import Path

import pytest

from tests.waiting import wait_until
from workbench.files.atomic import write_bytes_atomic, write_text_atomic
from workbench.files.workspace import workspace_folder
from workbench.labs.signoff.instructors import KdfParams, create_instructor
from workbench.labs.signoff.roster import offered_roster
from workbench.labs.signoff.signing import sign_off
from workbench.labs.signoff.signoff_errors import SignoffError
from workbench.labs.signoff.signoff_record import Evidence, RecordFields, record_digest
from workbench.labs.signoff.verify import course_evidence, verify_log
from workbench.labs.store.store import Store, StoreError, read_signoffs
from workbench.labs.store.workspace_rows import WorkspaceLimits, WorkspaceRefused
from workbench.labs.store.workspace_sync import (
    WorkspacePusher,
    push_file,
    remove_file,
    sync_at_start,
)
from workbench.labs.storecopy import copy_store
from workbench.sim.record import Recorder

FAST = KdfParams(n=2**10, r=8, p=1)
PASS = "correct horse battery"
MAZE = "5 4\n#####\n#S..#\n#..E#\n#####\n"


def test_a_file_is_kept_replaced_and_removed_with_a_growing_revision(store):
    first = store.workspaces.put("alice", "mazes/mine.txt", b"one", 100.0)
    again = store.workspaces.put("alice", "mazes/mine.txt", b"one", 200.0)
    second = store.workspaces.put("alice", "mazes/mine.txt", b"two!", 300.0)
    assert (first.revision, again.revision, second.revision) == (1, 1, 2)  # same bytes: kept
    row, data = store.workspaces.file("alice", "mazes/mine.txt")
    assert data == b"two!" and row.sha256 == hashlib.sha256(b"two!").hexdigest()
    assert row.size == 4 and row.mtime == 300.0
    assert store.workspaces.file("bob", "mazes/mine.txt") is None  # each student their own
    gone = store.workspaces.remove("alice", "mazes/mine.txt")
    assert gone is not None and gone.deleted and gone.revision == 3
    assert store.workspaces.file("alice", "mazes/mine.txt") is None
    assert store.workspaces.index("alice")["mazes/mine.txt"].deleted
    assert store.workspaces.remove("alice", "mazes/mine.txt") is None


def test_the_bounds_are_kept_and_each_refusal_says_which(store):
    limits = WorkspaceLimits(file_cap=10, quota=25, files=3)
    with pytest.raises(WorkspaceRefused, match=r"more than the .* a file may take"):
        store.workspaces.put("alice", "big.txt", b"x" * 11, 1.0, limits)
    store.workspaces.put("alice", "a.txt", b"x" * 10, 1.0, limits)
    store.workspaces.put("alice", "b.txt", b"x" * 10, 1.0, limits)
    with pytest.raises(WorkspaceRefused, match="more than its quota"):
        store.workspaces.put("alice", "c.txt", b"x" * 6, 1.0, limits)
    store.workspaces.put("alice", "c.txt", b"x" * 5, 1.0, limits)
    with pytest.raises(WorkspaceRefused, match="the most it may keep"):
        store.workspaces.put("alice", "d.txt", b"", 1.0, limits)
    # replacing a file counts its new size only, and a removed file frees its room
    store.workspaces.put("alice", "a.txt", b"y" * 10, 1.0, limits)
    store.workspaces.remove("alice", "b.txt")
    store.workspaces.put("alice", "d.txt", b"z" * 10, 1.0, limits)
    # another student's workspace has its own room
    store.workspaces.put("bob", "a.txt", b"x" * 10, 1.0, limits)
    kept = {p for p, r in store.workspaces.index("alice").items() if not r.deleted}
    assert kept == {"a.txt", "c.txt", "d.txt"}


@pytest.mark.parametrize(
    "name",
    ["../escape.txt", "/etc/passwd", "a/../../b", "runs//x", ".hidden", "a/.tmp", "tab\there",
     "x" * 256, "/".join(["d"] * 17) + "/f", "back\\slash", ""],
)  # fmt: skip
def test_names_that_are_not_plain_workspace_paths_are_refused(store, name):
    with pytest.raises(WorkspaceRefused):
        store.workspaces.put("alice", name, b"data", 1.0)
    assert store.workspaces.index("alice") == {}


def test_writes_racing_for_the_last_of_a_quota_cannot_both_pass(store, tmp_path):
    """Two connections each add a file that fits alone; together they would pass the quota."""
    limits = WorkspaceLimits(file_cap=100, quota=150, files=10)
    other = Store.open(store.data_dir, db=None if store.path else store.backend.url)
    results: list[str] = []
    start = threading.Barrier(2)

    def add(s: Store, name: str) -> None:
        start.wait()
        try:
            s.workspaces.put("alice", name, b"x" * 100, 1.0, limits)
            results.append("kept")
        except WorkspaceRefused:
            results.append("refused")

    threads = [threading.Thread(target=add, args=(s, n)) for s, n in ((store, "a"), (other, "b"))]
    for t in threads:
        t.start()
    for t in threads:
        t.join(30)
    other.close()
    assert sorted(results) == ["kept", "refused"]


# -- two lab servers, one course database ---------------------------------------------------


class Server:
    """One lab server's data folder on the course database."""

    def __init__(self, data_dir: Path, db: str):
        self.data_dir = data_dir
        self.db = db

    def workspace(self, user: str = "alice") -> Path:
        folder = workspace_folder(self.data_dir, user)
        folder.mkdir(parents=True, exist_ok=True)
        return folder

    def store(self) -> Store:
        return Store.open(self.data_dir, db=self.db)

    def save(self, rel: str, data: bytes, user: str = "alice") -> Path:
        """Save a file as the app does, and send it as the app's pusher does."""
        path = self.workspace(user) / rel
        path.parent.mkdir(parents=True, exist_ok=True)
        write_bytes_atomic(path, data)
        with self.store() as s:
            push_file(s, user, rel, self.workspace(user))
        return path


@pytest.fixture
def servers(tmp_path: Path, pg_url: str) -> tuple[Server, Server]:
    return Server(tmp_path / "one", pg_url), Server(tmp_path / "two", pg_url)


def test_a_file_saved_on_one_server_is_there_when_the_next_session_starts_on_the_other(servers):
    one, two = servers
    one.save("mazes/mine.txt", MAZE.encode())
    one.save("programs/wall.viple", b"<viple/>")
    report = sync_at_start(two.data_dir, two.db, "alice", two.workspace())
    assert sorted(report.fetched) == ["mazes/mine.txt", "programs/wall.viple"]
    assert (two.workspace() / "mazes/mine.txt").read_text() == MAZE
    assert (two.workspace() / "programs/wall.viple").read_bytes() == b"<viple/>"
    # changed on the second server, then the student is back on the first
    two.save("mazes/mine.txt", b"changed on two")
    (two.workspace() / "programs/wall.viple").unlink()
    with two.store() as s:
        remove_file(s, "alice", "programs/wall.viple", two.workspace())
    report = sync_at_start(one.data_dir, one.db, "alice", one.workspace())
    assert report.fetched == ["mazes/mine.txt"] and report.removed == ["programs/wall.viple"]
    assert (one.workspace() / "mazes/mine.txt").read_bytes() == b"changed on two"
    assert not (one.workspace() / "programs/wall.viple").exists()
    # nothing changed since: the next start brings nothing
    again = sync_at_start(one.data_dir, one.db, "alice", one.workspace())
    assert (again.fetched, again.removed, again.pushed, again.problems) == ([], [], [], [])


def test_files_changed_while_the_store_was_away_are_sent_at_the_next_start(servers):
    one, two = servers
    one.save("notes.txt", b"v1")
    sync_at_start(two.data_dir, two.db, "alice", two.workspace())
    # on the first server: a file changed, one added, one removed, none of them sent
    (one.workspace() / "notes.txt").write_bytes(b"v2, edited here")
    (one.workspace() / "new.txt").write_bytes(b"new")
    report = sync_at_start(one.data_dir, one.db, "alice", one.workspace())
    assert sorted(report.pushed) == ["new.txt", "notes.txt"]
    (one.workspace() / "new.txt").unlink()
    report = sync_at_start(one.data_dir, one.db, "alice", one.workspace())
    assert report.removed == ["new.txt"]
    later = sync_at_start(two.data_dir, two.db, "alice", two.workspace())
    assert later.fetched == ["notes.txt"]
    assert (two.workspace() / "notes.txt").read_bytes() == b"v2, edited here"
    assert not (two.workspace() / "new.txt").exists()


def test_a_file_changed_on_both_servers_keeps_the_one_modified_last(servers):
    one, two = servers
    one.save("a.txt", b"first")
    one.save("b.txt", b"first")
    sync_at_start(two.data_dir, two.db, "alice", two.workspace())
    # a.txt: changed on two (sent), then changed again on one later (not sent)
    two.save("a.txt", b"from two")
    (one.workspace() / "a.txt").write_bytes(b"from one, later")
    os.utime(one.workspace() / "a.txt", (4_000_000_000, 4_000_000_000))
    # b.txt: changed on one first (not sent), then on two (sent)
    (one.workspace() / "b.txt").write_bytes(b"from one, earlier")
    os.utime(one.workspace() / "b.txt", (1_000_000_000, 1_000_000_000))
    two.save("b.txt", b"from two, later")
    report = sync_at_start(one.data_dir, one.db, "alice", one.workspace())
    assert report.pushed == ["a.txt"] and report.fetched == ["b.txt"]
    assert (one.workspace() / "b.txt").read_bytes() == b"from two, later"
    sync_at_start(two.data_dir, two.db, "alice", two.workspace())
    assert (two.workspace() / "a.txt").read_bytes() == b"from one, later"


def test_a_run_record_here_is_never_replaced_by_another_copy_from_the_store(servers):
    """The sync keeps the one write rule of ~/runs: a record is written once, by the recorder,
    so a different copy under its name elsewhere never replaces this server's (issue 37)."""
    one, two = servers
    record = "runs/20250101-1/run-001.jsonl"
    one.save(record, b'{"type": "header"}\n')
    sync_at_start(two.data_dir, two.db, "alice", two.workspace())
    two.save(record, b'{"type": "header", "forged": true}\n')  # pushed from elsewhere
    os.utime(two.workspace() / record, (4_000_000_000, 4_000_000_000))
    report = sync_at_start(one.data_dir, one.db, "alice", one.workspace())
    assert report.fetched == []
    assert report.problems == [f"{record}: a run record is never changed once written: this "
                               "server's copy is kept"]  # fmt: skip
    assert (one.workspace() / record).read_bytes() == b'{"type": "header"}\n'


def test_a_file_past_the_bounds_stays_on_its_server_and_the_report_says_why(servers):
    one, two = servers
    big = one.workspace() / "big.bin"
    big.write_bytes(b"x" * (5 * 1024 * 1024 + 1))
    (one.workspace() / "ok.txt").write_bytes(b"fine")
    report = sync_at_start(one.data_dir, one.db, "alice", one.workspace())
    assert report.pushed == ["ok.txt"]
    assert any("big.bin" in p and "MiB" in p for p in report.problems)
    assert sync_at_start(two.data_dir, two.db, "alice", two.workspace()).fetched == ["ok.txt"]


def test_a_link_in_the_workspace_is_never_followed_or_sent(servers, tmp_path):
    one, _ = servers
    secret = tmp_path / "secret.txt"
    secret.write_text("not the student's")
    os.symlink(secret, one.workspace() / "link.txt")
    report = sync_at_start(one.data_dir, one.db, "alice", one.workspace())
    assert report.pushed == []
    with one.store() as s:
        assert s.workspaces.index("alice") == {}
        with pytest.raises(WorkspaceRefused, match=r"link\.txt"):
            push_file(s, "alice", "link.txt", one.workspace())


def test_a_run_record_made_on_one_server_is_signed_and_verified_from_the_course_store(
    servers, tmp_path
):
    one, two = servers
    record = one.workspace() / "runs" / "20260302-140509" / "run-1.jsonl"
    record.parent.mkdir(parents=True)
    recorder = Recorder(record)
    recorder.header(maze="mine.txt")
    recorder.summary({"exit_time": 41.5})
    # the app's pusher sends the record as it is closed
    told: list[str] = []
    pusher = WorkspacePusher(one.store, "alice", one.workspace(), told.append)
    pusher.start()
    try:
        recorder.close()
        assert pusher.wait_idle(30), pusher.waiting
    finally:
        pusher.stop()
    assert told == []
    digest = record_digest(record)
    record.unlink()  # as on any machine but the first server
    # the instructor signs at the second server: the record is checked from the store
    with two.store() as s:
        create_instructor(two.data_dir, "Dr Chen", PASS, kdf=FAST, store=s)
        roster = offered_roster(s)
        fields = RecordFields(
            student="alice", lab="unity-simulator", exercise="wall-following", driver="alice",
            evidence=Evidence(str(record), digest, {"exit_time": 41.5}), objectives_passed=True,
        )  # fmt: skip
        sign_off(s, "Dr Chen", PASS, fields)
        elsewhere = Evidence(str(record.with_name("run-2.jsonl")), "sha256:" + "0" * 64, {})
        with pytest.raises(SignoffError, match="neither on this machine nor in the course store"):
            sign_off(s, "Dr Chen", PASS, replace(fields, evidence=elsewhere))
    rows = read_signoffs(two.data_dir, two.db)
    with course_evidence(two.db) as evidence:
        [verdict] = verify_log(rows, roster, evidence=evidence).verdicts
    assert verdict.ok and "checked in the course store" in verdict.notes[0]
    # without the store the digest is not checked, as before
    [plain] = verify_log(rows, roster).verdicts
    assert "not present" in plain.notes[0]
    # the student removes the record: the copy kept with the sign-off still checks it
    rel = record.relative_to(one.workspace()).as_posix()
    with two.store() as s:
        remove_file(s, "alice", rel, two.workspace())
    with course_evidence(two.db) as evidence:
        [kept] = verify_log(rows, roster, evidence=evidence).verdicts
    assert kept.ok and "the copy kept when it was signed" in kept.notes[0]
    # copies changed in the database fail
    with two.store() as s, s.backend.write() as tx:
        tx.execute("UPDATE signoff_evidence SET content = ?", (b"{}",))
    with course_evidence(two.db) as evidence:
        [bad] = verify_log(rows, roster, evidence=evidence).verdicts
    assert not bad.ok and "no longer has the signed digest" in bad.problems[0]


def test_a_store_that_hangs_never_holds_up_a_save_and_the_file_goes_once_it_answers(
    pg_server, servers, monkeypatch
):
    """The course database stops answering (SIGSTOP) while the app saves: the save returns,
    the pusher keeps the file, tells the student once it keeps failing, and sends it when the
    database answers again."""
    monkeypatch.setenv("WORKBENCH_DB_TIMEOUT", "1")
    one, two = servers
    told: list[str] = []
    heard = threading.Event()

    def tell(text: str) -> None:
        told.append(text)
        heard.set()

    def open_store() -> Store:
        return Store.open(one.data_dir, db=one.db, offline_ok=True)

    pusher = WorkspacePusher(open_store, "alice", one.workspace(), tell, retry_first=0.2,
                             retry_most=0.5)  # fmt: skip
    pusher.start()
    pids = pg_server.freeze()
    safety = threading.Timer(60, pg_server.thaw, (pids,))
    safety.start()
    try:
        write_text_atomic(one.workspace() / "saved.txt", MAZE)  # returns: nothing waits
        assert pusher.waiting == ["saved.txt"]
        assert heard.wait(45), "the student was not told"
        assert "saved.txt is not in the course store yet" in told[0]
    finally:
        safety.cancel()
        pg_server.thaw(pids)
    try:
        assert pusher.wait_idle(45), pusher.waiting
        wait_until(lambda: len(told) == 2, timeout=10)
    finally:
        pusher.stop()
    assert told[1] == "~/saved.txt is in the course store now"
    report = sync_at_start(two.data_dir, two.db, "alice", two.workspace())
    assert report.fetched == ["saved.txt"]


def test_a_pusher_with_nothing_to_send_gives_its_connection_back(servers):
    import psycopg

    one, _ = servers

    def connections() -> int:
        with psycopg.connect(one.db) as conn:
            row = conn.execute(
                "SELECT count(*) FROM pg_stat_activity WHERE datname = current_database() "
                "AND application_name = 'viple-workbench'"
            ).fetchone()
        return int(row[0])

    told: list[str] = []
    pusher = WorkspacePusher(one.store, "alice", one.workspace(), told.append, idle_close=0.3)
    pusher.start()
    try:
        write_text_atomic(one.workspace() / "first.txt", MAZE)
        assert pusher.wait_idle(30)
        wait_until(lambda: connections() == 0, "the connection given back")
        write_text_atomic(one.workspace() / "second.txt", MAZE)  # a new one is opened
        assert pusher.wait_idle(30)
    finally:
        pusher.stop()
    with one.store() as s:
        assert {"first.txt", "second.txt"} <= set(s.workspaces.index("alice"))
    assert told == []


def test_a_file_the_store_refuses_is_said_at_once(servers):
    one, _ = servers
    told: list[str] = []
    pusher = WorkspacePusher(one.store, "alice", one.workspace(), told.append,
                             WorkspaceLimits(file_cap=4))  # fmt: skip
    pusher.start()
    try:
        write_text_atomic(one.workspace() / "long.txt", "more than four")
        assert pusher.wait_idle(30)
    finally:
        pusher.stop()
    assert len(told) == 1 and told[0].startswith("~/long.txt is kept on this server only")


def test_store_migrate_copies_the_workspaces(tmp_path, pg_url):
    data = tmp_path / "data"
    Store.open(data).close()
    alice = workspace_folder(data, "alice")
    (alice / "runs" / "20260302").mkdir(parents=True)
    (alice / "runs" / "20260302" / "run-1.jsonl").write_bytes(b'{"type":"header"}\n')
    (alice / "mine.txt").write_text(MAZE)
    (alice / ".mine.txt.abc.tmp").write_text("half written")  # the writer's: not copied
    bob = workspace_folder(data, "bob")
    bob.mkdir(parents=True)
    (bob / "huge.bin").write_bytes(b"x" * (5 * 1024 * 1024 + 1))
    with Store.open(data) as source, Store.open(tmp_path / "pg", db=pg_url) as target:
        report = copy_store(source, target)
        assert report.workspaces == {"alice": 2}
        assert any(why.startswith("bob: huge.bin") for why in report.left)
        assert target.workspaces.file("alice", "mine.txt")[1] == MAZE.encode()
        _row, data_ = target.workspaces.file("alice", "runs/20260302/run-1.jsonl")
        assert data_ == b'{"type":"header"}\n'
        assert set(target.workspaces.index("alice")) == {"mine.txt", "runs/20260302/run-1.jsonl"}
    # a second copy into the same database is refused: it holds the files already
    with (
        Store.open(data) as source,
        Store.open(tmp_path / "pg", db=pg_url) as target,
        pytest.raises(StoreError, match="already holds"),
    ):
        copy_store(source, target)
