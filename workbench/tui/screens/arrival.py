"""What lies under the names dialog when the workbench starts by asking who is at the robot.

The main screen is built once the names are given: a served student's first screen is then the
dialog alone, which costs an app about half the CPU of the dialog over the whole main screen.
That counts when a class logs in at the same moment and every app starts at once.
"""

from __future__ import annotations

from textual.screen import Screen

from ..host import OpenScreen


class ArrivalScreen(Screen[None]):
    """An empty screen under the names dialog; each time it is on top it asks for the main
    screen, which the app opens once the names are given (see ``WorkbenchApp.open_main``)."""

    def on_screen_resume(self) -> None:
        self.post_message(OpenScreen("main"))
