"""Work every served app does the same way at start, done once in the fork server.

Each SSH session's app is forked from the lab server's fork server (``workbench/ssh/
forkserver.py``), which calls the app's ``warm_up`` (``workbench/tui/app.py``) before it forks.
That hands :func:`prepare` the app a served student gets, and :func:`prepare` runs it once,
headless, to the screen a student sees first (the names dialog) and past it to the main
screen, and keeps what Textual parsed of the stylesheets on the way: every app parses the same
CSS (the app's file and the widgets' defaults) into the same rules, about a fifth of its CPU to
the first screen. The run also fills the caches of the libraries beneath (Rich's cell widths,
parsed colours and styles, Textual's compiled markup), which the forked apps then share.

A new app's stylesheet takes the kept rules in :func:`seed`, only when its CSS variables are
the ones they were parsed with (a different theme is parsed afresh, as before).
"""

from __future__ import annotations

import asyncio
import tempfile
from collections.abc import Callable
from typing import Any

from textual.app import App
from textual.css.stylesheet import Stylesheet

from .terminal_driver import plain_keys

#: the rules parsed ahead: Textual's parse cache key -> rule sets, and the variables used
_parsed: dict[tuple, list] = {}
_variables: dict[str, str] = {}
#: room in a stylesheet's parse cache for every source the app and its screens parse
PARSE_CACHE = 256


def prepare(make_app: Callable[[str], App[Any]]) -> None:
    """Run the app ``make_app(folder)`` makes (``folder``: an empty temporary folder for its
    data and files) headless to its first screen and keep the parsed stylesheets (and the
    served terminal driver's table of typed keys)."""
    plain_keys()

    async def first_screen() -> None:
        async with app.run_test(size=(80, 24)) as pilot:
            await pilot.pause()
            keep(app.stylesheet)
            await pilot.press("enter")  # past the names dialog: the main screen's CSS too
            await pilot.pause()
            keep(app.stylesheet)  # (Textual starts its parse cache afresh on the way)

    with tempfile.TemporaryDirectory(prefix="workbench-warmup-") as folder:
        app = make_app(folder)
        # more sources than Textual's parse cache holds by default (64): none may drop out
        app.stylesheet._parse_cache.maxsize = PARSE_CACHE
        _parsed.clear()
        _variables.clear()
        asyncio.run(first_screen())


def keep(stylesheet: Stylesheet) -> None:
    """Keep what ``stylesheet`` has parsed, beside what was kept before with the same CSS
    variables, for the apps made after this."""
    if _variables and stylesheet._variables != _variables:
        _parsed.clear()
    cache = stylesheet._parse_cache
    _parsed.update((key, cache[key]) for key in list(cache.keys()))
    _variables.clear()
    _variables.update(stylesheet._variables)


def seed(stylesheet: Stylesheet) -> int:
    """Give a new app's stylesheet the rules parsed ahead; how many sources it was given."""
    if not _parsed or stylesheet._variables != _variables:
        return 0
    cache = stylesheet._parse_cache
    cache.maxsize = max(cache.maxsize, PARSE_CACHE)
    for key, rules in _parsed.items():
        cache[key] = rules
    return len(_parsed)
