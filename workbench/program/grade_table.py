"""The grading table as CSV or JSON, and its summary in words.

The table holds only what the runs gave (no dates, no timings of the grading itself), so the
same folder graded again gives the same bytes. A CSV cell of text that a spreadsheet would take
for a formula (it starts with ``=``, ``+``, ``-``, ``@``, a tab or a carriage return: a
student chooses their file's name) is written with a ``'`` in front.
"""

from __future__ import annotations

import csv
import io
import json
from collections.abc import Sequence
from dataclasses import asdict
from pathlib import Path
from typing import TYPE_CHECKING, Any

from workbench.files.spreadsheet import spreadsheet_cell

from .grading import Plan, Row

if TYPE_CHECKING:
    from .submissions import Skipped

COLUMNS = (
    "student",
    "file",
    "program_sha256",
    "loads",
    "maze",
    "seed",
    "reached_exit",
    "time",
    "distance_blocks",
    "turn_degrees",
    "collisions",
    "errors",
    "refusal",
)
#: how many refused programs and skipped files the summary names
SHOWN_REFUSALS = 20
SHOWN_SKIPPED = 20


def csv_text(rows: Sequence[Row]) -> str:
    out = io.StringIO()
    writer = csv.writer(out, lineterminator="\n")
    writer.writerow(COLUMNS)
    for row in rows:
        writer.writerow([spreadsheet_cell(value) for value in _values(row)])
    return out.getvalue()


def json_text(
    rows: Sequence[Row], plan: Plan, what: dict[str, Any], skipped: Sequence[Skipped] = ()
) -> str:
    """The rows as JSON, under what was graded (``what``: the lab and exercise, or nothing)
    and the plan's mazes, seeds and profile; ``skipped``: the folder's files not graded,
    each with the reason."""
    data = {
        **what,
        "mazes": [_name(m) for m in plan.mazes],
        "seeds": plan.seeds,
        "profile": plan.profile,
        "max_time": plan.max_time,
        "rows": [asdict(row) for row in rows],
        "skipped": [asdict(s) for s in skipped],
    }
    return json.dumps(data, indent=1, ensure_ascii=False) + "\n"


def summary(rows: Sequence[Row]) -> list[str]:
    """The table in a few lines: programs, how many load, get out everywhere, are refused."""
    programs: dict[tuple[str, str], list[Row]] = {}
    for row in rows:
        programs.setdefault((row.student, row.file), []).append(row)
    loads = sum(all(r.loads for r in rs) for rs in programs.values())
    out = sum(all(r.reached_exit for r in rs) for rs in programs.values())
    refused = [rs for rs in programs.values() if any(r.refusal for r in rs)]
    lines = [
        f"{_many(len(programs), 'program')}, {_many(len(rows), 'run')}: "
        f"{loads} load, {out} reached the exit on every run, {len(refused)} refused on some run"
    ]
    for rs in refused[:SHOWN_REFUSALS]:
        reason = next(r.refusal for r in rs if r.refusal)
        named = reason.startswith(f"{rs[0].file}:")
        lines.append(f"  {reason}" if named else f"  {rs[0].file}: {reason}")
    if len(refused) > SHOWN_REFUSALS:
        lines.append(f"  and {len(refused) - SHOWN_REFUSALS} more (see the table)")
    return lines


def skipped_lines(skipped: Sequence[Skipped]) -> list[str]:
    """The files of the folder that were not graded, each with the reason (the first
    :data:`SHOWN_SKIPPED`; the JSON table lists them all)."""
    if not skipped:
        return []
    lines = [f"skipped {_many(len(skipped), 'file')} of the folder:"]
    lines += [f"  {s.file}: {s.reason}" for s in skipped[:SHOWN_SKIPPED]]
    if len(skipped) > SHOWN_SKIPPED:
        lines.append(f"  and {len(skipped) - SHOWN_SKIPPED} more (see the JSON table)")
    return lines


def _many(count: int, word: str) -> str:
    return f"{count} {word}" + ("" if count == 1 else "s")


def _values(row: Row) -> list[Any]:
    data = asdict(row)
    values = []
    for column in COLUMNS:
        value = data[column]
        if isinstance(value, bool):
            value = "yes" if value else "no"
        values.append("" if value is None else value)
    return values


def _name(path: str) -> str:
    return Path(path).name
