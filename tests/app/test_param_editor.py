"""The parameter editor of a starter FSM at 80x24: the FILL IN parameters are marked with the
lab's hint, and every parameter's whole range and default can be read."""

from __future__ import annotations

from textual.pilot import Pilot

from workbench.labs.checks import apply_setup
from workbench.labs.model import load_labs
from workbench.tui.app import make_app
from workbench.tui.dialogs.algorithm import AlgorithmModal
from workbench.tui.widgets.param_editor import ParamEditor
from workbench.wire.settings import AppSettings

from .support import run, screen_lines

EXERCISE = {lab.id: lab for lab in load_labs()}["unity-simulator"].exercise("wall-following")


def test_fill_in_parameters_are_marked_with_their_hint_and_full_range(tmp_path):
    app = make_app(AppSettings(paused=True, noise="off", data_dir=tmp_path / "data"))

    async def body(pilot: Pilot) -> None:
        apply_setup(app.station, EXERCISE.setup, lab="unity-simulator", exercise=EXERCISE.id)
        app.set_up_done(EXERCISE.setup)
        await pilot.press("g")
        await pilot.pause()
        modal = app.screen
        assert isinstance(modal, AlgorithmModal)
        editors = list(modal.query(ParamEditor))
        marked = [e.parameter.name for e in editors if e.has_class("-fill-in")]
        assert marked == ["open_right", "front_blocked", "right_turn", "left_turn"]
        details = modal.query_one("#alg-details")
        shown: set[str] = set()
        for y in range(0, 60, 4):  # scroll the details through, reading the terminal
            details.scroll_to(y=y, animate=False)
            await pilot.pause()
            box = details.region  # only the details column of the dialog
            lines = screen_lines(app)[box.y : box.bottom]
            shown.add(" ".join(" ".join(line[box.x : box.right] for line in lines).split()))
        seen = " ".join(shown)
        assert "right_turn 0 -360 to 360, default 0" in seen
        assert "left_turn 0 -360 to 360, default 0" in seen
        assert "FILL IN: degrees of Turn by Degree away from a wall ahead." in seen
        for editor in editors:
            hint = editor.hint
            if hint is not None:
                assert " ".join(f"FILL IN: {hint}".split()) in seen, hint

    run(app, body)
