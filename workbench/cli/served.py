"""The app of one SSH session, started from the settings the lab server made for it.

The lab server (``workbench/door/appproc.py``) hands a session's app its settings as one JSON
object (:meth:`workbench.wire.settings.AppSettings.to_json`), the workbench for a student and
the instructor's console (:mod:`workbench.tui.console_app`) for an instructor: to :func:`main`
in a process forked from the fork server, or as the one argument of
``python -m workbench.cli.served`` when it starts the app as a new process. The course
database's URL is never among them: the app finds it in its environment (``$WORKBENCH_DB``),
as the command line does without ``--db``.
"""

from __future__ import annotations

import json
import socket
import sys
from dataclasses import replace
from typing import TYPE_CHECKING

from workbench.labs.store.store import StoreError, resolve_db
from workbench.wire.settings import SESSION_FIELDS, AppSettings, SettingsError

from .common import error

if TYPE_CHECKING:
    from textual.app import App


def main(settings: object) -> int:
    """Run the app with ``settings`` (a JSON object); exit status 2 when they are not the
    app's or the app cannot start with them (the reason on standard error)."""
    from workbench.labs.model import LabFileError
    from workbench.tui.app import AppSetupError, make_app
    from workbench.tui.console_app import make_console

    app: App[None]
    try:
        given = _with_db(AppSettings.from_json(settings))
        # an instructor's session is the console: the class, the queue, signing with their
        # own key typed in their own terminal
        app = make_console(given) if given.role == "instructor" else make_app(given)
    except (SettingsError, StoreError, AppSetupError, LabFileError) as exc:
        error(str(exc))
        return 2
    app.run()
    return app.return_code or 0


def spare(template: object, control: socket.socket) -> int:
    """A spare app (``workbench/door/spares.py``): the workbench started from the settings
    every session shares (``template``, a JSON object; what is a session's own is left out),
    waiting at the names dialog for its session on ``control``
    (:mod:`workbench.tui.serving.seat`); then as :func:`main` with the session's settings."""
    from workbench.labs.model import LabFileError
    from workbench.tui.app import AppSetupError, make_app
    from workbench.tui.serving.seat import Seat

    try:
        if not isinstance(template, dict):
            raise SettingsError("the spare's settings are not a JSON object")
        shared = {k: v for k, v in template.items() if k not in SESSION_FIELDS}
        given = AppSettings.from_json(shared)
        if given.role != "student":
            raise SettingsError("a spare app is a student's workbench")
        app = make_app(given, Seat(control, _with_db))
    except (SettingsError, StoreError, AppSetupError, LabFileError) as exc:
        error(f"no spare app: {exc}")
        return 2
    app.run()
    return app.return_code or 0


def _with_db(settings: AppSettings) -> AppSettings:
    """A session's settings with the course database its environment names."""
    return replace(settings, db=resolve_db(None))


def run(argv: list[str]) -> int:
    """``python -m workbench.cli.served SETTINGS``: the settings as one JSON argument."""
    if len(argv) != 1:
        error("give the app's settings as one JSON object")
        return 2
    try:
        settings = json.loads(argv[0])
    except ValueError as exc:
        error(f"the app's settings are not JSON: {exc}")
        return 2
    return main(settings)


if __name__ == "__main__":
    raise SystemExit(run(sys.argv[1:]))
