"""Fixtures of the sign-off, store and course-store tests."""

from __future__ import annotations

from pathlib import Path

import pytest

from workbench.labs.signoff.instructors import create_instructor
from workbench.labs.store.store import Store

from .signoff_support import FAST, PASS


@pytest.fixture
def data_dir(tmp_path, config_dir) -> Path:
    """A lab machine's data folder: instructor Dr Chen, trusted in the test's own roster, and
    the database with nothing signed yet."""
    d = tmp_path / "data"
    create_instructor(d, "Dr Chen", PASS, kdf=FAST, trusted=config_dir / "roster.json")
    Store.open(d).close()
    return d


@pytest.fixture(params=["sqlite", "postgresql"])
def store(request, tmp_path: Path):
    """An empty course store, once on the SQLite file in a data folder and once on a database
    of its own on the PostgreSQL server."""
    db = request.getfixturevalue("pg_url") if request.param == "postgresql" else None
    with Store.open(tmp_path / "data", db=db) as opened:
        yield opened
