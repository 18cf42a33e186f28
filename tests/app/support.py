"""What the app tests share: running async test bodies, driving an app with a Pilot, an app
that hosts one screen, and reading what the screens show."""

from __future__ import annotations

import asyncio
import functools
from collections.abc import Awaitable, Callable, Coroutine
from pathlib import Path
from typing import Any

from textual import events
from textual.app import App
from textual.pilot import Pilot
from textual.screen import Screen
from textual.widgets import Input

from workbench.tui.host import ScreenHost
from workbench.tui.screens.main import MainScreen
from workbench.tui.widgets.run_status import RunStatus


def sync(test: Callable[..., Coroutine[Any, Any, None]]) -> Callable[..., None]:
    """Run an ``async def`` test body with asyncio (the suite has no async test plugin)."""

    @functools.wraps(test)
    def run(*args: Any, **kwargs: Any) -> None:
        asyncio.run(test(*args, **kwargs))

    return run


def run(
    app: App,
    body: Callable[[Pilot], Awaitable[None]],
    size: tuple[int, int] = (80, 24),
) -> None:
    """Start ``app`` headless at ``size``, let it settle, then run ``body`` with its pilot."""

    async def go() -> None:
        async with app.run_test(size=size) as pilot:
            await pilot.pause()
            await body(pilot)

    asyncio.run(go())


class Host(ScreenHost):
    """An app that pushes one screen (``under_test``) over an empty default screen, keeps what
    the screen was dismissed with (``results``) and what was said on the message line
    (``said``). It draws in plain ASCII unless ``follow_unicode``: then as the screen does (its
    footer, scroll bars and dialogs too), as the workbench app would."""

    def __init__(self, screen: Screen, follow_unicode: bool = False) -> None:
        super().__init__()
        self.under_test = screen
        self.results: list[object] = []
        self.said: list[str] = []
        if follow_unicode:
            self.set_reactive(ScreenHost.unicode, bool(getattr(screen, "unicode", False)))

    def say(self, text: str) -> None:
        self.said.append(text)
        super().say(text)

    def on_mount(self) -> None:
        self.push_screen(self.under_test, self.results.append)


async def burst(pilot: Pilot, *keys: tuple[str, str | None]) -> None:
    """Post ``keys`` to the app in one go, as a packet's keys come, then let them settle."""
    for key, char in keys:
        pilot.app.post_message(events.Key(key, char))
    for _ in range(3):
        await pilot.pause()


def still(pilot: Pilot) -> None:
    """No blinking text cursors in the picture (for a snapshot)."""
    for field in pilot.app.screen.query(Input):
        field.cursor_blink = False


def maze_file(folder: Path, rows: str, profile: str = "unity", name: str = "room") -> str:
    """The maze ``rows`` saved as ``name``.txt in ``folder``, named ``name`` and made for
    ``profile``; its path, as the command line takes it."""
    path = folder / f"{name}.txt"
    path.write_text(f"---\nname: {name}\nprofile: {profile}\n---\n{rows}")
    return str(path)


def said(app: App) -> str:
    """What the workbench's message line says now."""
    return next(s for s in app.screen_stack if isinstance(s, MainScreen)).message


def run_panel(app: App) -> str:
    """The main screen's run panel (who drives, time, measures, the VIPLE connection line)."""
    main = next(s for s in app.screen_stack if isinstance(s, MainScreen))
    return "\n".join(main.query_one(RunStatus).lines)


def screen_lines(app: App) -> list[str]:
    """The text the terminal shows now, row by row (dialogs over the screens below them)."""
    import io

    from rich.console import Console

    width, height = app.size
    console = Console(
        width=width,
        height=height,
        file=io.StringIO(),
        force_terminal=True,
        record=True,
        legacy_windows=False,
        safe_box=False,
    )
    console.print(
        app.screen._compositor.render_update(full=True, screen_stack=app._background_screens)
    )
    return console.export_text().splitlines()


async def endpoints_started(app) -> None:
    """Wait until the app's VIPLE endpoints have started: the workers that start them are done
    (not every worker: a screen may keep one reading the store for as long as it is open)."""
    starting = [w for w in app.workers if w.group == "endpoints"]
    if starting:  # (an empty list would make Textual wait for every worker)
        await app.workers.wait_for_complete(starting)


def terminal_output(app: App) -> str:
    """What the app writes to a terminal to draw the whole screen now (dialogs over the
    screens below them): the characters and escape sequences a real terminal receives."""
    update = app.screen._compositor.render_update(full=True, screen_stack=app._background_screens)
    return update.render_segments(app.console)


def emulated_terminal(app: App):
    """A VT emulator (pyte) that has been sent :func:`terminal_output`: its title, and the
    text it shows row by row (``.display``)."""
    import pyte

    width, height = app.size
    terminal = pyte.Screen(width, height)
    pyte.Stream(terminal).feed(terminal_output(app))
    return terminal
