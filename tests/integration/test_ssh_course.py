"""Two lab servers on loopback sharing one PostgreSQL store: a student who passed an
objective on one finds it passed on the other, where the labs reopen at the same exercise,
and finds there the files saved on the first."""

from __future__ import annotations

import pytest

from tests.app.support import sync
from workbench.files.workspace import workspace_folder
from workbench.labs.store.store import Store
from workbench.labs.store.workspace_sync import push_file

from .ssh_support import Account, lab_host, open_exercise

DRIVE = "Unity simulator: Drive by wire"
KEYS_DONE = "[X] drove with w, a, s, d and space"


@pytest.mark.long
@sync
async def test_a_student_moves_between_two_servers_sharing_one_database(
    tmp_path, pg_url, monkeypatch
):
    monkeypatch.setenv("WORKBENCH_DB", pg_url)  # as serve-ssh --db hands it to its apps
    ann = Account("ann")
    async with (
        lab_host(tmp_path / "one", [ann], db=pg_url) as one,
        lab_host(tmp_path / "two", [ann], db=pg_url) as two,
    ):
        term = await one.terminal("ann", size=(100, 30))
        await term.start_app()
        await open_exercise(term, DRIVE)
        term.send("a")  # the exercise's set-up (KEYS_DONE below shows it took)
        # its message may give way at once to news of the course database on the same line
        await term.wait_until(
            lambda t: "set up: unity" in t or "the course database is back" in t,
            "the set-up's message",
        )
        term.send("\x1b")
        await term.wait_gone("esc Back")
        for key in "wasd ":
            term.send(key)
        term.send("l")
        await term.wait_for(KEYS_DONE)
        await term.close()
        # a maze saved in the workspace on server one (as a file transfer saves one)
        first = workspace_folder(one.data_dir, "ann")
        (first / "mine.txt").write_text("3 3\n###\n#S#\n###\n")
        with Store.open(one.data_dir, db=pg_url) as store:
            push_file(store, "ann", "mine.txt", first)

        again = await two.terminal("ann", size=(100, 30))
        await again.start_app()
        second = workspace_folder(two.data_dir, "ann")
        assert (second / "mine.txt").read_text() == (first / "mine.txt").read_text()
        again.send("l")
        await again.wait_for("esc Back", "r Ready")
        screen = await again.wait_until(
            lambda t: "loading saved work" not in t, "the saved work read"
        )
        assert DRIVE in screen.splitlines()[0]  # reopened at the exercise left on server one
        assert KEYS_DONE in screen
        await again.close()
    assert not (tmp_path / "one" / "data" / "workbench.sqlite3").exists()
    assert not (tmp_path / "two" / "data" / "workbench.sqlite3").exists()
    with Store.open(tmp_path / "three", db=pg_url) as store:
        assert ("unity-simulator", "drive-by-wire") in store.progress.of("ann")
