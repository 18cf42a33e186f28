"""serve-ssh names at start the store its sessions keep students' work in, never a password."""

from pathlib import Path

from workbench.cli.ssh import store_words


def test_a_course_database_is_named_without_its_password():
    said = store_words(Path("/srv/lab"), "postgresql://lab:s3cret@db.example:5432/course")
    assert said == "the course database postgresql://lab:***@db.example:5432/course"
    assert "s3cret" not in said


def test_without_a_database_the_sqlite_file_is_named():
    said = store_words(Path("/srv/lab"), None)
    assert said == "SQLite in the data folder, /srv/lab/workbench.sqlite3"
