"""The free-text answer fields of every lab at 80×24: each hint drawn whole (a multiple-choice
question's choices are checked in test_labs_keys.py)."""

from __future__ import annotations

from rich.cells import cell_len
from textual.pilot import Pilot
from textual.widgets import Input, OptionList

from tests.waiting import until
from workbench.labs.model import load_labs
from workbench.tui.screens.labs import LabsScreen

from .labs_support import lab_app, open_labs
from .support import run


def test_no_answer_hint_is_cut(tmp_path):
    app = lab_app(tmp_path / "data")
    asked = [
        (f"{lab.id}/{exercise.id}", exercise)
        for lab in load_labs()
        for exercise in lab.exercises
        if exercise.questions
    ]
    assert any(not q.choices for _, exercise in asked for q in exercise.questions)

    async def body(pilot: Pilot) -> None:
        await open_labs(pilot)
        screen = app.screen
        assert isinstance(screen, LabsScreen)
        listing = screen.query_one("#labs-list", OptionList)
        for option_id, exercise in asked:
            listing.highlighted = listing.get_option_index(option_id)
            await pilot.pause()
            for q in exercise.questions:
                if q.choices:
                    continue
                field = screen.query_one(f"#q-{q.id}", Input)
                # the exercise's fields are laid out after they are mounted
                await until(lambda f=field: f.content_region.width > 0, f"{option_id} laid out")
                hint = str(field.placeholder)
                assert 0 < cell_len(hint) <= field.content_region.width, (option_id, hint)

    run(app, body)
