"""The class as a grid: every student (rows) in every exercise of one lab (columns).

Opened from the console with ``g``; ``l`` shows the next lab. Each cell says where the student
stands: signed off, waiting for sign-off, every objective passed, or how many pass, with a
mark where a question waits for the instructor. The grid follows the console's reads of the
store (it holds none of its own); the student column stays while the table scrolls, and the
copy hints (two students' evidence on one program file) stand under it.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any, ClassVar, Protocol

from textual.app import ComposeResult
from textual.binding import BindingType
from textual.screen import Screen
from textual.widgets import DataTable, Static

from workbench.labs.classview import ASKED, NOTHING, PASSED, SIGNED, ClassView, Standing
from workbench.labs.evidence_text import short_digest

from ..host import FollowsUnicode
from ..keys import bindings
from ..plain import follow_app
from ..widgets.key_bar import KeyBar


class ClassSource(Protocol):
    """Where the grid reads the class from (the console screen): its last read, the hooks it
    calls with each read, and its Unicode setting."""

    view: ClassView | None
    on_shown: list[Callable[[Any], None]]
    unicode: bool


#: the widest an exercise's heading line is (its id wraps at its hyphens, never cut)
HEADING_WIDTH = 10


def passed_mark(unicode: bool) -> str:
    return "✓" if unicode else "ok"


def cell_text(standing: Standing, unicode: bool) -> str:
    """One student in one exercise, in a few characters."""
    words = {SIGNED: "signed", ASKED: "waiting", PASSED: passed_mark(unicode), NOTHING: ""}
    text = words.get(standing.state, f"{standing.passed}/{standing.of}")
    return text + ("?" if standing.waiting_questions else "")


def heading_lines(exercise: str, width: int = HEADING_WIDTH) -> list[str]:
    """An exercise id on lines of at most ``width`` characters, broken after its hyphens (a
    part longer than that stands whole on its line)."""
    parts = [p + "-" for p in exercise.split("-")]
    parts[-1] = parts[-1][:-1]
    lines = [""]
    for part in parts:
        if lines[-1] and len(lines[-1]) + len(part) > width:
            lines.append("")
        lines[-1] += part
    return lines


def legend(unicode: bool) -> str:
    return (
        f"{passed_mark(unicode)} all objectives pass, 2/3 objectives passing, waiting: asked "
        "for sign-off, signed: signed off, ?: a question waits for you"
    )


class GridScreen(FollowsUnicode, Screen[None]):
    """Students by exercises, one lab at a time, live with the console's reads."""

    DEFAULT_CSS = """
    GridScreen #grid-title {
        height: 1;
        text-style: bold;
        color: $text-primary;
        padding: 0 1;
    }
    GridScreen #grid-table {
        height: 1fr;
    }
    GridScreen #grid-legend {
        height: auto;
        padding: 0 1;
        color: $text-muted;
    }
    GridScreen #grid-hints {
        height: auto;
        max-height: 4;
        padding: 0 1;
        color: $text-warning;
    }
    """

    BINDINGS: ClassVar[list[BindingType]] = [*bindings("grid.lab", "grid.leave")]

    def __init__(self, console: ClassSource) -> None:
        super().__init__()
        self.console = console
        #: which lab's exercises the columns are (an index into the grid's labs)
        self.lab_index = 0
        self.unicode = console.unicode
        self._shown: tuple[object, ...] | None = None

    def compose(self) -> ComposeResult:
        yield Static("", id="grid-title", markup=False)
        yield DataTable(id="grid-table", cursor_type="row", zebra_stripes=True, fixed_columns=1)
        yield Static("", id="grid-legend", markup=False)
        yield Static("", id="grid-hints", markup=False)
        yield KeyBar()

    def on_mount(self) -> None:
        follow_app(self)
        self.console.on_shown.append(self._read)
        self.query_one(DataTable).focus()
        self.lab_index = self._busiest_lab()
        self.show()

    def _busiest_lab(self) -> int:
        """The lab most students have an exercise of open (the first lab when none has)."""
        labs, view = self.labs(), self.view
        if view is None or not labs:
            return 0
        open_in = [row.lab for row in view.rows if row.lab in labs]
        return labs.index(max(labs, key=open_in.count)) if open_in else 0

    def on_unmount(self) -> None:
        if self._read in self.console.on_shown:
            self.console.on_shown.remove(self._read)

    def _read(self, message: object) -> None:
        self.show()

    def set_unicode(self, unicode: bool) -> None:
        self.unicode = unicode
        self._shown = None
        self.show()

    @property
    def view(self) -> ClassView | None:
        return self.console.view

    def labs(self) -> tuple[str, ...]:
        view = self.view
        return view.grid.labs() if view is not None else ()

    def show(self) -> None:
        """The chosen lab's columns and every student's row, from the console's last read."""
        view = self.view
        labs = self.labs()
        title = self.query_one("#grid-title", Static)
        if view is None or not labs:
            title.update("Class by exercise: reading the class..." if view is None else
                         "Class by exercise: no exercises in the labs")  # fmt: skip
            return
        self.lab_index %= len(labs)
        lab = labs[self.lab_index]
        grid = view.grid
        exercises = [ex for lab_id, ex in grid.exercises if lab_id == lab]
        more = f"; l: next lab ({self.lab_index + 1} of {len(labs)})" if len(labs) > 1 else ""
        count = len(grid.students)
        people = f"{count} student{'' if count == 1 else 's'}"
        title.update(f"Class by exercise, lab {lab}: {people}{more}")
        rows = [
            (student, *(cell_text(grid.standing(student, lab, ex), self.unicode)
                        for ex in exercises))
            for student in grid.students
        ]  # fmt: skip
        shown = (lab, self.unicode, tuple(exercises), tuple(rows))
        if shown != self._shown:
            self._shown = shown
            self._fill(exercises, rows)
        self.query_one("#grid-legend", Static).update(legend(self.unicode))
        self.query_one("#grid-hints", Static).update("\n".join(self._hint_lines(view)))

    def _fill(self, exercises: Sequence[str], rows: Sequence[tuple[str, ...]]) -> None:
        table = self.query_one(DataTable)
        row = table.cursor_row
        headings = [heading_lines(ex) for ex in exercises]
        table.clear(columns=True)
        table.header_height = max((len(h) for h in headings), default=1)
        names = [r[0] for r in rows]
        table.add_column("Student", width=max(len("Student"), *map(len, names), 1), key="student")
        for i, (ex, lines) in enumerate(zip(exercises, headings, strict=True)):
            cells = [r[i + 1] for r in rows]
            width = max(max(map(len, lines)), *map(len, cells), 1)
            table.add_column("\n".join(lines), width=width, key=ex)
        for shown in rows:
            table.add_row(*shown, key=shown[0])
        if rows:
            table.move_cursor(row=min(max(row, 0), len(rows) - 1))

    def _hint_lines(self, view: ClassView) -> list[str]:
        lines = []
        for hint in view.hints:
            where = sorted({f"{u.lab}/{u.exercise}" for u in hint.uses})
            lines.append(
                f"same program {hint.name} ({short_digest(hint.digest)}): "
                f"{', '.join(hint.students)} in {', '.join(where)}"
            )
        return lines

    def action_next_lab(self) -> None:
        self.lab_index += 1
        self.show()

    def action_leave(self) -> None:
        self.dismiss(None)
