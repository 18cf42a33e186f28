"""matplotlib is loaded only when a picture is drawn: never by importing the app, by making
it, or by importing the pictures package itself (the served app's start-up stays as it was)."""

from __future__ import annotations

import subprocess
import sys

CHECK = """
import sys
import workbench.tui.app as app_module
print("after import:", "matplotlib" in sys.modules)
from workbench.wire.settings import AppSettings
app = app_module.make_app(AppSettings())
print("after make_app:", "matplotlib" in sys.modules)
import workbench.pictures.render, workbench.pictures.runs
print("after pictures:", "matplotlib" in sys.modules)
import workbench.cli.served, workbench.cli
print("after the served entry point and the command line:", "matplotlib" in sys.modules)
"""


def test_the_app_never_loads_matplotlib(tmp_path):
    done = subprocess.run(
        [sys.executable, "-c", CHECK],
        capture_output=True,
        text=True,
        cwd=tmp_path,
        env={"HOME": str(tmp_path), "PATH": "/usr/bin:/bin"},
        timeout=120,
    )
    assert done.returncode == 0, done.stderr
    assert done.stdout.split("\n")[:4] == [
        "after import: False",
        "after make_app: False",
        "after pictures: False",
        "after the served entry point and the command line: False",
    ]


def test_drawing_loads_it(tmp_path):
    """The check above can fail: drawing a picture does load matplotlib."""
    from tests.pictures.records import bend_record
    from workbench.pictures.render import PictureSpec, render
    from workbench.pictures.runs import load_runs

    render(load_runs([bend_record(tmp_path)]), PictureSpec())
    assert "matplotlib" in sys.modules
