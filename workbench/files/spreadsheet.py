"""Cells of the CSV files the workbench writes for spreadsheets (the grade table, the
gradebook): a text a student chose (a file name, a driver's name, a note) that begins like a
formula is written with a leading apostrophe, so a spreadsheet shows it and never runs it."""

from __future__ import annotations

from typing import Any

#: how a cell a spreadsheet would take as a formula (or as a formula's lead-in) begins
FORMULA_START = ("=", "+", "-", "@", "\t", "\r")


def spreadsheet_cell(value: Any) -> Any:
    """``value`` as a CSV cell: text that begins like a formula gets a leading ``'``."""
    if isinstance(value, str) and value.startswith(FORMULA_START):
        return "'" + value
    return value
