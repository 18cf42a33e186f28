"""What a student keeps across app restarts, the names asked at start, and the VIPLE endpoint
a VIPLE exercise's set-up starts."""

from __future__ import annotations

from textual.pilot import Pilot
from textual.widgets import Input, OptionList, Static

from workbench.labs.store.store import Store
from workbench.tui.app import make_app
from workbench.tui.dialogs.identity import IdentityDialog
from workbench.tui.screens.main import MainScreen
from workbench.viple.tcp_server import TcpConfig
from workbench.wire.settings import AppSettings

from .labs_support import (
    DRIVE,
    lab_app,
    objective_lines,
    open_exercise,
    open_labs,
    text,
    try_answer,
)
from .support import endpoints_started, run, run_panel, said

CONNECT = "web-simulator/connect"


def test_an_exercise_is_saved_as_soon_as_it_is_opened(tmp_path):
    app = lab_app(tmp_path / "data")

    async def body(pilot: Pilot) -> None:
        await open_exercise(pilot, DRIVE)
        saved = app.store.progress.of("ana")[("unity-simulator", "drive-by-wire")]
        assert saved["passed"] is False
        assert [o["passed"] for o in saved["objectives"]] == [False, False, False]

    run(app, body)


def test_what_passed_before_a_restart_is_still_passed_after_it(tmp_path):
    data = tmp_path / "data"
    first = lab_app(data)

    async def drive(pilot: Pilot) -> None:
        screen = await open_exercise(pilot, DRIVE)
        await pilot.press("a", "escape", "w", "a", "s", "d", "space", "l")
        await pilot.pause()
        assert text(screen, "#labs-objectives").startswith("[X] drove with w, a, s, d and space")
        try_answer(screen, "tcp-port", "13")  # tried just before the app dies
        await pilot.pause()

    run(first, drive)
    again = lab_app(data)  # a new process: a fresh robot that has not moved

    async def resume(pilot: Pilot) -> None:
        screen = await open_exercise(pilot, DRIVE)
        lines = objective_lines(screen)
        kept = "[X] drove with w, a, s, d and space: passed earlier: used w, a, s, d, space"
        assert lines[0] == kept
        assert lines[1].startswith("[ ] edited the maze")
        assert screen.query_one("#q-tcp-port", Input).value == "13"
        saved = again.store.progress.of("ana")[("unity-simulator", "drive-by-wire")]
        assert saved["objectives"][0]["evidence"]["keys_used"] == ["a", "d", "s", "space", "w"]

    run(again, resume)


def test_the_names_are_asked_at_start_and_shown_on_the_message_line(tmp_path):
    app = make_app(AppSettings(paused=True, student="ana", data_dir=tmp_path, ask_names=True))

    async def body(pilot: Pilot) -> None:
        assert isinstance(app.screen, IdentityDialog)
        assert app.screen.query_one("#student", Input).value == "ana"
        app.screen.query_one("#partner", Input).value = "Ana"
        await pilot.press("enter")
        await pilot.pause()
        assert "the partner is the student" in text(app.screen, "#error")
        app.screen.query_one("#partner", Input).value = "Ben Ortiz"
        app.screen.query_one("#partner", Input).focus()
        await pilot.press("enter")
        await pilot.pause()
        assert isinstance(app.screen, MainScreen)
        assert (app.student, app.partner) == ("ana", "Ben Ortiz")
        assert text(app.screen, "#message").rstrip().endswith("ana & Ben Ortiz (student)")
        await open_labs(pilot)
        assert app.screen.partner == "Ben Ortiz"

    run(app, body)


def test_over_ssh_the_student_name_is_fixed_and_escape_keeps_the_defaults(tmp_path):
    app = make_app(AppSettings(paused=True, student="ana", data_dir=tmp_path, ask_names=True,
                   student_fixed=True))  # fmt: skip

    async def body(pilot: Pilot) -> None:
        assert app.screen.query_one("#student", Input).disabled
        await pilot.press("escape")
        await pilot.pause()
        assert isinstance(app.screen, MainScreen)
        assert (app.student, app.partner) == ("ana", "")

    run(app, body)


def test_a_served_students_first_screen_is_the_names_dialog_alone_then_the_main_screen(
    tmp_path,
):
    # the main screen is built once the names are given (a class logging in at once waits
    # less for its first screens); what was said before it existed is on its message line
    hint = "VIPLE: on your computer run  ssh -N -p 2222 -L 1350:localhost:41000 ana@lab"
    app = make_app(AppSettings(paused=True, student="ana", data_dir=tmp_path, ask_names=True,
                   student_fixed=True, connect_hint=hint))  # fmt: skip

    async def body(pilot: Pilot) -> None:
        await pilot.pause()
        assert isinstance(app.screen, IdentityDialog)
        assert not any(isinstance(s, MainScreen) for s in app.screen_stack)
        await pilot.press("enter")
        await pilot.pause()
        assert isinstance(app.screen, MainScreen)
        assert text(app.screen, "#message").startswith("VIPLE from your computer: press ?")
        assert text(app.screen, "#message").rstrip().endswith("ana (student)")
        await pilot.press("w")  # the main screen drives at once
        await pilot.press("p")
        await pilot.pause(0.3)
        assert app.station.session.world.time > 0

    run(app, body)


def test_a_connect_hint_is_shown_at_start_and_in_the_help(tmp_path):
    hint = "VIPLE: on your computer run  ssh -N -p 2222 -L 1350:localhost:41000 ana@lab"
    app = make_app(AppSettings(paused=True, student="ana", data_dir=tmp_path, connect_hint=hint))

    async def body(pilot: Pilot) -> None:
        await pilot.pause()
        assert text(app.screen, "#message").startswith("VIPLE: on your computer run")
        await pilot.press("question_mark")
        await pilot.pause()
        assert hint in str(app.screen.query_one("#help-connect", Static).render())

    run(app, body, size=(100, 30))


def test_a_connect_hint_too_long_for_the_message_line_points_to_the_help(tmp_path):
    hint = (
        "VIPLE: on your computer run  ssh -N -p 2222 -L 1350:localhost:41000 "
        "-R 41001:localhost:8124 ana@lab.example.edu  then VIPLE uses localhost:1350"
    )
    app = make_app(AppSettings(paused=True, student="ana", data_dir=tmp_path, connect_hint=hint,
                   ask_names=True, student_fixed=True))  # fmt: skip

    async def body(pilot: Pilot) -> None:
        await pilot.press("enter")  # the names dialog
        await pilot.pause()
        line = text(app.screen, "#message")
        assert line.startswith("VIPLE from your computer: press ? for the ssh command")
        assert line.rstrip().endswith("ana (student)")
        await pilot.press("question_mark")
        await pilot.pause()
        shown = str(app.screen.query_one("#help-connect", Static).render())
        assert "-R 41001:localhost:8124" in shown.replace("\n", " ")

    run(app, body)


def test_the_set_up_of_a_websocket_exercise_starts_the_websocket_client(tmp_path):
    app = lab_app(tmp_path / "data")

    async def body(pilot: Pilot) -> None:
        assert app.endpoints is None
        screen = await open_exercise(pilot, CONNECT)
        await pilot.press("a")
        await endpoints_started(app)
        await pilot.pause()
        assert app.endpoints is not None and app.endpoints.ws is not None
        assert app.endpoints.ws.config.url == "ws://localhost:8124/"
        assert "robot connects to ws://localhost:8124/" in said(app)
        assert "VIPLE ws waiting for ws://localhost:8124/" in run_panel(app)
        assert screen is app.screen

    run(app, body)


def test_the_set_up_of_a_tcp_exercise_starts_listening(tmp_path):
    app = lab_app(tmp_path / "data")

    async def body(pilot: Pilot) -> None:
        app._viple_configs = (TcpConfig(port=0), None)  # any free port, not 1350
        text_shown = await app.open_endpoint("tcp")
        port = app.endpoints.tcp.port
        assert port > 0 and text_shown == f"VIPLE: connect your program (TCP) to localhost:{port}"
        assert f"VIPLE tcp listening on 127.0.0.1:{port}" in run_panel(app)
        assert await app.open_endpoint("tcp") == text_shown  # already listening: the same

    run(app, body)


def test_a_store_with_unreadable_progress_says_so_and_starts_that_exercise_afresh(tmp_path):
    data = tmp_path / "data"
    with Store.open(data) as store:
        store.progress.save("ana", "unity-simulator", "drive-by-wire", {"objectives": 3})
    app = lab_app(data)

    async def body(pilot: Pilot) -> None:
        screen = await open_exercise(pilot, DRIVE)
        message = text(screen, "#labs-message")
        assert message == "saved progress unreadable (starts afresh): unity-simulator/drive-by-wire"
        assert text(screen, "#labs-objectives").startswith("[ ] drove")

    run(app, body)


def test_a_bundled_maze_is_never_saved_over_the_editor_asks_where(tmp_path):
    from workbench.files.bundled import default_maze_path
    from workbench.tui.dialogs.path import PathDialog
    from workbench.tui.screens.editor import EditorScreen

    bundled = default_maze_path()
    before = bundled.read_bytes()
    app = lab_app(tmp_path / "data")

    async def body(pilot: Pilot) -> None:
        assert app.maze_path == bundled
        await pilot.press("e")
        await pilot.pause()
        assert isinstance(app.screen, EditorScreen) and app.screen.editor.path is None
        await pilot.press("right", "space", "ctrl+s")
        await pilot.pause()
        assert isinstance(app.screen, PathDialog)  # save as, not over the bundled file
        await pilot.press("escape", "escape")  # no save; leaving asks: discard
        await pilot.pause()
        await pilot.press("d")
        await pilot.pause()
        await open_exercise(pilot, DRIVE)
        await pilot.press("a", "escape", "e")  # after a lab's set-up: its maze, still asked
        await pilot.pause()
        assert app.maze_path.name == "unity-default.txt"
        assert app.screen.editor.path is None

    run(app, body)
    assert bundled.read_bytes() == before


def test_the_labs_reopen_at_the_exercise_the_student_had_open(tmp_path):
    data = tmp_path / "data"
    first = lab_app(data)

    async def browse(pilot: Pilot) -> None:
        await open_exercise(pilot, "unity-simulator/wall-following")

    run(first, browse)
    with Store.open(data) as store:
        assert store.progress.place("ana") == ("unity-simulator", "wall-following")
        assert store.progress.place("ben") is None
    again = lab_app(data)

    async def resume(pilot: Pilot) -> None:
        await open_labs(pilot)
        screen = again.screen
        assert "Wall following" in text(screen, "#labs-title")
        listing = screen.query_one("#labs-list", OptionList)
        assert listing.highlighted_option.id == "unity-simulator/wall-following"

    run(again, resume)


def test_a_websocket_url_can_wait_until_asked_and_v_connects(tmp_path):
    url = "ws://127.0.0.1:9/"  # nothing listens: the client keeps trying, as it should
    app = make_app(
        AppSettings(paused=True, student="ana", data_dir=tmp_path, ws_url=url, ws_at_start=False)
    )

    async def body(pilot: Pilot) -> None:
        assert app.endpoints is None  # no connection attempts until asked
        await pilot.press("v")
        await endpoints_started(app)
        await pilot.pause()
        assert app.endpoints.ws is not None and app.endpoints.ws.config.url == url
        assert said(app) == (
            f"VIPLE: start your program's WebSocket server; the robot connects to {url}"
        )

    run(app, body)


def test_the_names_dialog_refuses_a_look_alike_name_and_normalises_the_rest(tmp_path):
    app = make_app(AppSettings(paused=True, student="ana", data_dir=tmp_path, ask_names=True))

    async def body(pilot: Pilot) -> None:
        partner = app.screen.query_one("#partner", Input)
        partner.value = "Bеn"  # a Cyrillic е
        partner.focus()
        await pilot.press("enter")
        await pilot.pause()
        assert isinstance(app.screen, IdentityDialog)
        assert "mixes letters of different scripts (Cyrillic, Latin)" in text(app.screen, "#error")
        partner.value = "Ben\u200b"  # a zero-width space
        await pilot.press("enter")
        await pilot.pause()
        assert "invisible formatting characters (U+200B" in text(app.screen, "#error")
        partner.value = "Ｂｅｎ"  # full-width letters: the same name
        await pilot.press("enter")
        await pilot.pause()
        assert isinstance(app.screen, MainScreen)
        assert (app.student, app.partner) == ("ana", "Ben")

    run(app, body)
