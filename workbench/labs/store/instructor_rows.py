"""The instructors' roster and sealed keys as a course database (PostgreSQL) keeps them; a
data folder's SQLite store keeps them in the folder's files instead
(:class:`~workbench.labs.signoff.roster.FileRosterKeys`)."""

from __future__ import annotations

from .database import StoreError
from .rows import Rows


class InstructorRows:
    """The ``instructors`` table over the store's connection."""

    def __init__(self, rows: Rows) -> None:
        self.rows = rows

    def entries(self) -> list[tuple[str, str, str]]:
        """(name, public key, added) of each instructor in the database's roster."""
        rows = self.rows.read(
            "SELECT name, public_key, added FROM instructors ORDER BY added, name"
        )
        return [(str(n), str(k), str(a)) for n, k, a in rows]

    def key_file(self, name: str) -> str | None:
        """The encrypted key file (JSON text) of an instructor, if the database holds it."""
        rows = self.rows.read("SELECT key_file FROM instructors WHERE name = ?", (name,))
        return str(rows[0][0]) if rows and rows[0][0] is not None else None

    def add(self, name: str, public_key: str, added: str, key_file: str | None) -> None:
        """Add an instructor (refused if the name is taken: a roster entry is never replaced)."""
        with self.rows.write() as tx:
            taken = tx.execute("SELECT 1 FROM instructors WHERE name = ?", (name,)).fetchone()
            if taken:
                raise StoreError(f"{name} is already in the roster in {self.rows.where}")
            tx.execute(
                "INSERT INTO instructors (name, public_key, added, key_file) VALUES (?, ?, ?, ?)",
                (name, public_key, added, key_file),
            )

    def count(self) -> int:
        return int(self.rows.read("SELECT count(*) FROM instructors")[0][0])
