"""Two lab servers on loopback sharing one PostgreSQL store: a student who passed an
objective on one finds it passed on the other, where the labs reopen at the same exercise."""

from __future__ import annotations

import pytest

from tests.app.support import sync
from workbench.labs.store import Store

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
        lab_host(tmp_path / "one", [ann]) as one,
        lab_host(tmp_path / "two", [ann]) as two,
    ):
        term = await one.terminal("ann", size=(100, 30))
        await term.start_app()
        await open_exercise(term, DRIVE)
        term.send("a")  # the exercise's set-up
        await term.wait_for("set up: unity")
        term.send("\x1b")
        await term.wait_gone("esc Back")
        for key in "wasd ":
            term.send(key)
        term.send("l")
        await term.wait_for(KEYS_DONE)
        await term.close()

        again = await two.terminal("ann", size=(100, 30))
        await again.start_app()
        again.send("l")
        await again.wait_for("esc Back", "Sign off")
        screen = await again.wait_until(
            lambda t: "loading saved work" not in t, "the saved work read"
        )
        assert DRIVE in screen.splitlines()[0]  # reopened at the exercise left on server one
        assert KEYS_DONE in screen
        await again.close()
    assert not (tmp_path / "one" / "data" / "workbench.sqlite3").exists()
    assert not (tmp_path / "two" / "data" / "workbench.sqlite3").exists()
    with Store.open(tmp_path / "three", db=pg_url) as store:
        assert ("unity-simulator", "drive-by-wire") in store.progress("ann")
