"""Fixtures shared by every test folder: a PostgreSQL server for the store's tests; and the
order the tests run in.

One server per test process (each pytest-xdist worker is one), started the first time a test
asks for it and stopped when the process ends; each test gets a database of its own on it.
Where no server can start, the tests that need one are skipped with the reason.
"""

from __future__ import annotations

import itertools
import os
from pathlib import Path

import pytest
from hypothesis import settings

import workbench.sim.record

from .full_disk import FakeDisk
from .pgserver import NoServer, PgServer

# hypothesis's own per-example deadline (200 ms) is a wall-clock rate: on a loaded machine a
# case that passes takes longer and fails as "unreliable". Tests assert behaviour, never speed.
settings.register_profile("workbench", deadline=None)
settings.load_profile("workbench")

_names = itertools.count(1)


def pytest_collection_modifyitems(items: list[pytest.Item]) -> None:
    """Tests marked ``long`` run first, the rest in their usual order. With several workers
    (``-n``) a long test that started last would keep the run going on one worker while the
    others have finished; started first, the short ones fill in around it."""
    items.sort(key=lambda item: item.get_closest_marker("long") is None)


@pytest.fixture(scope="session")
def pg_server():
    try:
        server = PgServer.create()
    except NoServer as exc:
        pytest.skip(f"no PostgreSQL server can start here: {exc}")
    yield server
    server.destroy()


@pytest.fixture
def pg_url(pg_server: PgServer) -> str:
    """A new, empty database on the session's server."""
    return pg_server.create_database(f"t{next(_names)}")


@pytest.fixture(autouse=True)
def _own_folders(tmp_path_factory, monkeypatch):
    """Every test runs with a home, configuration and data folders of its own (never the
    user's): the app keeps the last pair of names and the labs' progress in the data folder,
    and ``instructor add`` writes the trusted roster to the configuration folder. Whatever a
    test or a program it starts writes by default lands inside its temporary folders."""
    base = tmp_path_factory.mktemp("home")
    folders = {
        "HOME": base,
        "XDG_CONFIG_HOME": base / ".config",
        "XDG_DATA_HOME": base / ".local" / "share",
        "XDG_STATE_HOME": base / ".local" / "state",
        "XDG_CACHE_HOME": base / ".cache",
        "WORKBENCH_CONFIG": base / "workbench-config",
        "WORKBENCH_DATA": base / "workbench-data",
    }
    for name, folder in folders.items():
        folder.mkdir(parents=True, exist_ok=True)
        monkeypatch.setenv(name, str(folder))
    # a course database named by the environment would be the user's, not the test's
    monkeypatch.delenv("WORKBENCH_DB", raising=False)


@pytest.fixture
def disk(monkeypatch: pytest.MonkeyPatch) -> FakeDisk:
    """Run records are written to a disk a test can fill (``disk.full = True``)."""
    fake = FakeDisk()
    monkeypatch.setattr(workbench.sim.record, "open", fake.open, raising=False)
    return fake


@pytest.fixture
def config_dir(_own_folders) -> Path:
    """The test's own configuration folder (``$WORKBENCH_CONFIG``), where ``instructor add``
    keeps the instructor's trusted roster."""
    return Path(os.environ["WORKBENCH_CONFIG"])
