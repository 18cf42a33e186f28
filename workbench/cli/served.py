"""The app of one SSH session, started from the settings the lab server made for it.

The lab server (``workbench/ssh/appproc.py``) hands a session's app its settings as one JSON
object (:meth:`workbench.tui.settings.AppSettings.to_json`): to :func:`main` in a process
forked from the fork server, or as the one argument of ``python -m workbench.cli.served`` when
it starts the app as a new process. The course database's URL is never among them: the app
finds it in its environment (``$WORKBENCH_DB``), as the command line does without ``--db``.
"""

from __future__ import annotations

import json
import sys
from dataclasses import replace

from workbench.labs.store import StoreError, resolve_db
from workbench.tui.settings import AppSettings, SettingsError

from .common import error


def main(settings: object) -> int:
    """Run the app with ``settings`` (a JSON object); exit status 2 when they are not the
    app's or the app cannot start with them (the reason on standard error)."""
    from workbench.tui.app import AppSetupError, make_app

    try:
        given = AppSettings.from_json(settings)
        app = make_app(replace(given, db=resolve_db(None)))
    except (SettingsError, StoreError, AppSetupError) as exc:
        error(str(exc))
        return 2
    app.run()
    return app.return_code or 0


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
