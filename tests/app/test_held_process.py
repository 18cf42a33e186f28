"""The app that holds its process for its whole life (the one ``workbench`` starts on a
terminal, or a served session's) freezes what start-up built after its first screen, so the
garbage collector's full passes leave it alone and the robot drives without their stutter; an
app made in a process that makes many (a test's) leaves the collector as it is."""

from __future__ import annotations

import gc

import pytest

from workbench.cli import main
from workbench.tui.app import WorkbenchApp, make_app
from workbench.wire.settings import AppSettings

from .support import run


def test_the_app_workbench_starts_on_a_terminal_holds_its_process(tmp_path, monkeypatch):
    held: list[bool] = []

    def start(app: WorkbenchApp) -> None:  # instead of taking over the terminal
        held.append(app.holds_process)

    monkeypatch.setenv("TEXTUAL_DRIVER", "textual.drivers.headless_driver:HeadlessDriver")
    monkeypatch.setattr(WorkbenchApp, "run", start)
    assert main(["--student", "ann", "--record-dir", str(tmp_path / "runs")]) == 0
    assert held == [True]


@pytest.mark.parametrize("holds", [True, False])
def test_an_app_that_holds_its_process_freezes_its_start_up_objects(tmp_path, monkeypatch, holds):
    frozen: list[int] = []
    monkeypatch.setattr(gc, "freeze", lambda: frozen.append(1))
    app = make_app(AppSettings(paused=True, student="ann", record_dir=tmp_path / "runs"))
    app.holds_process = holds

    async def check(pilot) -> None:
        await pilot.pause()
        await pilot.pause()
        assert frozen == ([1] if holds else [])

    run(app, check)
