"""The students' work in the store: each exercise's saved progress, the exercise each student
had open last (their place) and who of a pair drove an exercise.

Every save here may be kept pending while a course database is away (see
:class:`~workbench.labs.store.store.Store`): its return value says whether it reached the database,
and every read includes what is still pending.
"""

from __future__ import annotations

import json
from datetime import datetime
from typing import Any

from ..names import name_key
from .database import StoreError
from .pending import PendingWrite
from .rows import Rows, stamp_of


class ProgressRows:
    """Progress, places and drivers, over the store's connection."""

    def __init__(self, rows: Rows) -> None:
        self.rows = rows

    # exercise progress

    def save(
        self,
        student: str,
        lab: str,
        exercise: str,
        progress: dict[str, Any],
        now: datetime | None = None,
    ) -> bool:
        """Replace the saved progress of one student in one exercise (any JSON object).
        True when written; False when kept pending (the database is away)."""
        text = json.dumps(progress, sort_keys=True, allow_nan=False)
        return self.rows.keep(
            PendingWrite("progress", (student, lab, exercise, text, stamp_of(now)))
        )

    def of(self, student: str, lab: str | None = None) -> dict[tuple[str, str], dict]:
        """Saved progress by (lab, exercise), including what is still pending."""
        sql = "SELECT lab, exercise, progress FROM progress WHERE student = ?"
        params: tuple[Any, ...] = (student,)
        if lab:
            sql += " AND lab = ?"
            params += (lab,)
        out: dict[tuple[str, str], dict] = {}
        for lab_id, exercise, text in self.rows.read(sql, params):
            try:
                out[(lab_id, exercise)] = json.loads(text)
            except json.JSONDecodeError:
                raise StoreError(
                    f"{self.rows.where}: the saved progress of {student} in {lab_id}/{exercise} "
                    "is not JSON"
                ) from None
        for write in self.rows.waiting():
            key = write.key
            if key[0] == "progress" and key[1] == student and (not lab or key[2] == lab):
                out[(key[2], key[3])] = json.loads(write.values[3])
        return out

    def spelling(self, name: str) -> str:
        """``name`` as the store already spells it when it holds progress, a place or a
        sign-off of that student with other case or spacing (``alice  doe`` finds
        ``Alice Doe``); else ``name`` itself."""
        key = name_key(name)
        sql = (
            "SELECT student FROM progress UNION SELECT student FROM places "
            "UNION SELECT student FROM signoffs"
        )
        known = sorted({str(row[0]) for row in self.rows.read(sql, ())})
        kept = {w.key[1] for w in self.rows.waiting() if w.key[0] in ("progress", "place")}
        known += sorted(kept)
        if name in known:
            return name
        return next((k for k in known if name_key(k) == key), name)

    # where each student was

    def set_place(self, student: str, lab: str, exercise: str, now: datetime | None = None) -> bool:
        """Remember the exercise ``student`` has open (the labs reopen there)."""
        return self.rows.keep(PendingWrite("place", (student, lab, exercise, stamp_of(now))))

    def place(self, student: str) -> tuple[str, str] | None:
        """The (lab, exercise) ``student`` had open last, if any."""
        kept = [w for w in self.rows.waiting() if w.key == ("place", student)]
        if kept:
            return (kept[-1].values[1], kept[-1].values[2])
        rows = self.rows.read("SELECT lab, exercise FROM places WHERE student = ?", (student,))
        return (rows[0][0], rows[0][1]) if rows else None

    def places(self) -> dict[str, tuple[str, str]]:
        """The (lab, exercise) every student who has opened one had open last."""
        rows = self.rows.read("SELECT student, lab, exercise FROM places ORDER BY student")
        return {str(s): (str(lab), str(ex)) for s, lab, ex in rows}

    # drivers

    def set_driver(
        self,
        student: str,
        partner: str,
        lab: str,
        exercise: str,
        driver: str,
        now: datetime | None = None,
    ) -> bool:
        """Record who drove (did the typing in) an exercise for a student or a pair."""
        values = (student, partner, lab, exercise, driver, stamp_of(now))
        return self.rows.keep(PendingWrite("driver", values))

    def drivers(self, student: str, partner: str = "") -> dict[tuple[str, str], str]:
        rows = self.rows.read(
            "SELECT lab, exercise, driver FROM drivers WHERE student = ? AND partner = ?",
            (student, partner),
        )
        return {(lab, exercise): driver for lab, exercise, driver in rows}
