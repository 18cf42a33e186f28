"""The database URL a lab server or a command is given: refused clearly when it is not a
PostgreSQL URL, and never printed with its password."""

from __future__ import annotations

import pytest
from hypothesis import given
from hypothesis import strategies as st

from workbench.labs.store.database import StoreError, redact, resolve_db

SAFE = st.text(
    st.characters(blacklist_characters="@:/?#", blacklist_categories=("Cs",)), min_size=1
)


def test_the_option_wins_over_the_environment_and_nothing_means_sqlite(monkeypatch):
    monkeypatch.setenv("WORKBENCH_DB", "postgresql://env@db/course")
    assert resolve_db("postgresql://opt@db/course") == "postgresql://opt@db/course"
    assert resolve_db(None) == "postgresql://env@db/course"
    monkeypatch.setenv("WORKBENCH_DB", "")
    assert resolve_db(None) is None
    assert resolve_db("sqlite") is None


@pytest.mark.parametrize(
    ("given_url", "expected"),
    [
        ("mysql://root@db/x", "--db: 'mysql://root@db/x' is not a PostgreSQL URL"),
        ("/var/lib/workbench.sqlite3", "is not a PostgreSQL URL"),
        ("postgresql://" + "a" * 3000, "longer than 2048 characters"),
    ],
)
def test_what_is_not_a_postgresql_url_is_refused_saying_what_to_write(given_url, expected):
    with pytest.raises(StoreError, match=r"postgresql://USER|longer") as caught:
        resolve_db(given_url)
    assert expected in str(caught.value)


@given(user=SAFE, password=SAFE, host=SAFE, query=SAFE)
def test_a_password_is_never_shown(user, password, host, query):
    url = f"postgresql://{user}:{password}@{host}:5432/course?sslpassword={query}"
    shown = redact(url)
    assert shown.startswith(f"postgresql://{user}:***@"[:200])
    assert f":{password}@" not in shown and "sslpassword" not in shown


@given(st.text(max_size=300))
def test_any_text_gives_a_url_or_a_store_error(text):
    try:
        assert resolve_db(text) in (None, text.strip())
    except StoreError as exc:
        assert "PostgreSQL URL" in str(exc) or "longer than" in str(exc)
