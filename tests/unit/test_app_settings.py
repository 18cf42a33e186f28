"""The app's settings: what the command line gives is what the app gets, a session's settings
reach its app whole as JSON, the course database's URL never travels with them, and settings
that are not the app's are refused with the setting named."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from workbench.cli import app_settings, build_parser
from workbench.cli.served import run
from workbench.door.appproc import AppSpec
from workbench.wire.settings import AppSettings, SettingsError


def test_the_command_line_gives_the_app_its_settings(monkeypatch):
    monkeypatch.delenv("SSH_CONNECTION", raising=False)
    args = build_parser().parse_args(
        ["--maze", "m.txt", "--profile", "web", "--seed", "7", "--unicode", "--tcp-port", "0",
         "--ws-url", "ws://127.0.0.1:8124/", "--ws-when-asked", "--student", "ana",
         "--partner", "ben", "--record-dir", "runs", "--workspace", "ws"]
    )  # fmt: skip
    settings = app_settings(args, db=None)
    assert settings.maze_path == Path("m.txt") and settings.workspace == Path("ws")
    assert (settings.profile, settings.seed, settings.unicode) == ("web", 7, True)
    assert settings.tcp_port is None  # port 0: no TCP endpoint
    assert settings.ws_url == "ws://127.0.0.1:8124/" and not settings.ws_at_start
    assert (settings.student, settings.partner) == ("ana", "ben")
    assert not settings.ask_names and settings.student_fixed  # named on the command line
    # without a name the app asks, and the login name may be changed there
    asked = app_settings(build_parser().parse_args([]), db=None)
    assert asked.ask_names and not asked.student_fixed and asked.tcp_port == 1350


def test_a_sessions_settings_reach_its_app_whole_as_json(tmp_path):
    spec = AppSpec("ann", "instructor", 41000, 41001, "hint", tmp_path, tmp_path / "r", tmp_path)
    settings = spec.settings()
    sent = json.loads(json.dumps(settings.to_json()))
    assert AppSettings.from_json(sent) == settings
    assert settings.role == "instructor" and settings.record_dir == tmp_path / "r"


def test_the_database_url_is_never_sent_nor_shown():
    settings = AppSettings(student="ann", db="postgresql://lab:secret@db.example/course")
    assert "secret" not in json.dumps(settings.to_json())
    assert "secret" not in repr(settings)
    with pytest.raises(SettingsError, match="unknown setting 'db'"):
        AppSettings.from_json({"db": "postgresql://lab:secret@db.example/course"})


@pytest.mark.parametrize(
    ("sent", "message"),
    [
        ({"colour": "red"}, "unknown setting 'colour': the app's settings are maze_path, "),
        ({"seed": "7"}, "setting 'seed' must be a whole number, not '7'"),
        ({"tick_hz": True}, "setting 'tick_hz' must be a number, not True"),
        ({"maze_path": 3}, "setting 'maze_path' must be text or null, not 3"),
        (["--student", "ann"], "the app's settings must be a JSON object, not list"),
    ],
)
def test_settings_that_are_not_the_apps_are_refused_by_name(sent, message):
    with pytest.raises(SettingsError) as refused:
        AppSettings.from_json(sent)
    assert str(refused.value).startswith(message)


def test_a_session_app_with_bad_settings_exits_2_and_says_why(capsys):
    assert run(["{not json"]) == 2
    assert "the app's settings are not JSON" in capsys.readouterr().err
    assert run([json.dumps({"student": "ann", "seed": "x"})]) == 2
    assert "workbench: setting 'seed' must be a whole number, not 'x'" in capsys.readouterr().err
    assert run([json.dumps({"profile": "lego"})]) == 2
    assert "unknown profile 'lego'" in capsys.readouterr().err
