"""Fixtures shared by every test folder: a PostgreSQL server for the store's tests; and the
order the tests run in.

One server per test process (each pytest-xdist worker is one), started the first time a test
asks for it and stopped when the process ends; each test gets a database of its own on it.
Where no server can start, the tests that need one are skipped with the reason.
"""

from __future__ import annotations

import itertools

import pytest

import workbench.sim.record

from .full_disk import FakeDisk
from .pgserver import NoServer, PgServer

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
def _own_data_folder(tmp_path_factory, monkeypatch):
    """Every test's default data folder is a fresh one (never the user's): the app keeps the
    last pair of names and the labs' progress there."""
    monkeypatch.setenv("WORKBENCH_DATA", str(tmp_path_factory.mktemp("data")))


@pytest.fixture
def disk(monkeypatch: pytest.MonkeyPatch) -> FakeDisk:
    """Run records are written to a disk a test can fill (``disk.full = True``)."""
    fake = FakeDisk()
    monkeypatch.setattr(workbench.sim.record, "open", fake.open, raising=False)
    return fake
