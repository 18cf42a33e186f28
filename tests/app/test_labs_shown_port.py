"""The Unity lab's TCP-port question takes the port the student's screen shows: over SSH each
session's workbench listens on a port of its own (the run panel says which), and 1350, the
simulator's, still counts; any other number does not."""

from __future__ import annotations

from textual.pilot import Pilot
from textual.widgets import Input, Static

from tests.sessions import free_port

from .labs_support import lab_app, open_exercise, text, try_answer
from .support import endpoints_started, run, run_panel, screen_lines


def test_the_port_the_screen_shows_answers_the_tcp_port_question(tmp_path):
    port = free_port()
    app = lab_app(tmp_path / "data", tcp_port=port)

    async def body(pilot: Pilot) -> None:
        await endpoints_started(app)
        app.refresh_views()
        await pilot.pause()
        assert f"127.0.0.1:{port}" in run_panel(app)  # what the student reads
        screen = await open_exercise(pilot)
        field = screen.query_one("#q-tcp-port", Input)
        reason = field.parent.query_one(".question-reason", Static)

        async def answer(value: str) -> str:
            try_answer(screen, "tcp-port", value)  # typed and tried with enter
            await pilot.pause()
            return str(reason.render())

        assert (await answer(str(port + 1))).endswith("not the expected answer (1 try)")
        shown = await answer(str(port))
        assert "correct: the TCP port your workbench shows" in shown
        assert "not answered yet: tcp-port" not in text(screen, "#labs-objectives")
        assert "question answered" in " ".join(screen_lines(app))
        assert (await answer("1350")).endswith("correct (3 tries)")

    run(app, body)
