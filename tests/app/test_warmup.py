"""The fork server's warm-up: an app made after it parses none of the CSS kept, and shows the
same first screen as an app that parsed everything itself; an app whose CSS variables differ
parses afresh."""

from __future__ import annotations

import pytest
import textual.css.stylesheet as stylesheet_module
from textual.css.stylesheet import Stylesheet

from workbench.door.forkserver import preload
from workbench.tui.app import make_app, warm_up
from workbench.tui.serving import warmup
from workbench.wire.settings import AppSettings

from .support import run, screen_lines


@pytest.fixture
def fresh_warmup():
    """No rules kept before or after the test (other tests parse as they always did)."""
    warmup._parsed.clear()
    warmup._variables.clear()
    yield
    warmup._parsed.clear()
    warmup._variables.clear()


def first_screen(tmp_path, parses: list[str]) -> list[str]:
    """The names dialog over the main screen of a served student's app, as the terminal
    shows it; each CSS source parsed on the way is added to ``parses``."""
    app = make_app(
        AppSettings(
            paused=True,  # nothing on the screen changes with time
            student="ann",
            ask_names=True,
            student_fixed=True,
            data_dir=tmp_path / "data",
            workspace=tmp_path / "ann",
            connect_hint="VIPLE: on your computer run ssh",
        ),
    )
    shown: list[str] = []

    async def look(pilot) -> None:
        await pilot.app.workers.wait_for_complete()
        await pilot.pause(0.2)  # everything the app does at start has been drawn
        shown.extend(screen_lines(pilot.app))

    real_parse = stylesheet_module.parse

    def counted(scope, css, read_from, *args, **kwargs):
        parses.append(str(read_from))
        return real_parse(scope, css, read_from, *args, **kwargs)

    stylesheet_module.parse = counted
    try:
        run(app, look)
    finally:
        stylesheet_module.parse = real_parse
    return shown


def test_after_the_warm_up_an_app_parses_no_css_and_shows_the_same_first_screen(
    tmp_path, fresh_warmup
):
    cold: list[str] = []
    before = first_screen(tmp_path / "cold", cold)
    assert any("app.tcss" in source for source in cold)
    assert "Who is at this robot?" in "\n".join(before)

    warm_up()
    warm: list[str] = []
    after = first_screen(tmp_path / "warm", warm)
    assert warm == [], warm
    assert after == before


def test_an_app_with_other_css_variables_is_not_given_the_kept_rules(tmp_path, fresh_warmup):
    warm_up()
    kept = len(warmup._parsed)
    assert kept > 10
    same = Stylesheet(variables=dict(warmup._variables))
    assert warmup.seed(same) == kept
    other = Stylesheet(variables={**warmup._variables, "primary": "#ff0000"})
    assert warmup.seed(other) == 0
    assert len(other._parse_cache) == 0


calls: list[str] = []


def _called_by_the_fork_server() -> None:
    calls.append("prepared")


def test_the_fork_server_calls_the_functions_it_is_given_after_importing():
    calls.clear()
    modules = preload(("workbench.tui.app", f"{__name__}:_called_by_the_fork_server"))
    assert calls == ["prepared"]
    assert modules > 100
