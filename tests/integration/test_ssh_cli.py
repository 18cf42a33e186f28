"""``workbench ssh add-user/list-users`` and ``workbench serve-ssh`` as an administrator uses
them: scripted passwords, key files, a clear refusal of a broken users file, the host key."""

from __future__ import annotations

import os
import signal
import stat
import subprocess
import sys
import time

import asyncssh
import pytest

from tests.sessions import free_port
from workbench.door.users import load_users
from workbench.ssh.server import ServerConfig


def workbench(*args: str, stdin: str = "", timeout: float = 60) -> subprocess.CompletedProcess:
    return subprocess.run(
        [sys.executable, "-m", "workbench", *args],
        input=stdin,
        capture_output=True,
        text=True,
        timeout=timeout,
    )


def test_add_user_reads_a_password_from_a_script_and_keys_from_pub_files(tmp_path):
    data = tmp_path / "data"
    pub = tmp_path / "id_ed25519.pub"
    pub.write_bytes(asyncssh.generate_private_key("ssh-ed25519").export_public_key())
    done = workbench(
        "ssh",
        "add-user",
        "ann",
        "--role",
        "student",
        "--key",
        str(pub),
        "--password",
        "--data-dir",
        str(data),
        stdin="lab-password\nlab-password\n",
    )
    assert done.returncode == 0, done.stderr
    assert "ann (student) can log in with 1 key and a password" in done.stdout
    user = load_users(data / "ssh-users.yaml")["ann"]
    assert user.accepts_password("lab-password") and len(user.keys) == 1

    short = workbench(
        "ssh",
        "add-user",
        "bo",
        "--role",
        "student",
        "--password",
        "--data-dir",
        str(data),
        stdin="short\n",
    )
    assert short.returncode == 2 and "at least 8 characters" in short.stderr
    private = tmp_path / "id_ed25519"
    private.write_bytes(asyncssh.generate_private_key("ssh-ed25519").export_private_key())
    wrong = workbench(
        "ssh", "add-user", "bo", "--role", "student", "--key", str(private), "--data-dir", str(data)
    )
    assert wrong.returncode == 2 and "give the .pub file" in wrong.stderr

    listed = workbench("ssh", "list-users", "--data-dir", str(data))
    assert listed.returncode == 0
    assert listed.stdout.startswith("ann  student     SHA256:") and "password" in listed.stdout


def test_serve_ssh_refuses_a_broken_users_file_naming_line_and_fix(tmp_path):
    users = tmp_path / "users.yaml"
    users.write_text("users:\n  ann:\n    role: pupil\n    password: x\n")
    done = workbench(
        "serve-ssh", "--users", str(users), "--data-dir", str(tmp_path / "d"), "--port", "0"
    )
    assert done.returncode == 2
    assert f"{users}:3:11: users.ann.role: unknown role 'pupil'" in done.stderr
    assert "(hint: use one of student, instructor)" in done.stderr
    assert "the server did not start" in done.stderr


@pytest.mark.parametrize(
    ("options", "message"),
    [
        (["--port", "99999"], "--port 99999 is not a port: use 1-65535"),
        (["--port", "41500"], "--port 41500 lies inside --port-range 41000-41999"),
        (["--port-range", "5-3"], "--port-range '5-3': ports must be 1024-65535"),
        (["--max-sessions", "0"], "must be > 0"),
        (["--max-connections-per-user", "0"], "--max-connections-per-user 0: must be at least 1"),
        (["--max-terminal", "wide"], "--max-terminal 'wide': write it as COLUMNSxROWS"),
        (["--max-terminal", "40x10"], "the app needs at least 80x24"),
        (["--app-memory", "10"], "--app-memory 10: give at least 64"),
        (["--max-channels-per-connection", "0"], "--max-channels-per-connection 0: must be at"),
        (["--channel-grace", "0"], "--channel-grace 0: must be > 0"),
        (["--server-memory", "50"], "--server-memory 50: give at least 128"),
        (["--penalty-max", "-1"], "--penalty-min and --penalty-max must be 0 or more"),
        (["--unauthenticated-grace", "0"], "--unauthenticated-grace, --max-unauthenticated"),
        (["--proxy-protocol", "10.0.0.5,lb"], "--proxy-protocol 'lb' is not an address or net"),
    ],
)
def test_serve_ssh_refuses_bad_options_before_it_starts(tmp_path, options, message):
    done = workbench("serve-ssh", "--data-dir", str(tmp_path / "d"), *options)
    assert done.returncode == 2
    assert message in done.stderr
    assert not (tmp_path / "d").exists()  # nothing made: no host key, no log


def test_serve_ssh_makes_a_private_host_key_logs_and_stops_on_sigterm(tmp_path):
    data = tmp_path / "data"
    port = free_port(ServerConfig.port_range)
    server = subprocess.Popen(
        [
            sys.executable,
            "-m",
            "workbench",
            "serve-ssh",
            "--bind",
            "127.0.0.1",
            "--port",
            str(port),
            "--data-dir",
            str(data),
        ],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    try:
        log = data / "ssh.log"
        deadline = time.monotonic() + 30
        while "serving on 127.0.0.1 port" not in (log.read_text() if log.exists() else ""):
            assert server.poll() is None and time.monotonic() < deadline, server.stderr.read()
            time.sleep(0.1)
        key = data / "ssh_host_ed25519_key"
        assert stat.S_IMODE(os.stat(key).st_mode) == 0o600
        fingerprint = asyncssh.read_private_key(key).get_fingerprint()
        assert fingerprint in log.read_text()
        server.send_signal(signal.SIGTERM)
        assert server.wait(15) == 0
        assert "no users yet" in server.stderr.read()
    finally:
        if server.poll() is None:
            server.kill()
            server.wait()
