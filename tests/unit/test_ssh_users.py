"""The SSH users file: what it accepts, and errors that name the file, line, key and fix."""

from __future__ import annotations

import os
import stat

import asyncssh
import pytest

from workbench.door.passwords import hash_password
from workbench.door.users import UsersFile, UsersFileError, add_user, load_users, parse_users

KEY = asyncssh.generate_private_key("ssh-ed25519")
PUB = KEY.export_public_key().decode().strip()
OTHER = asyncssh.generate_private_key("ssh-ed25519").export_public_key().decode().strip()
HASH = hash_password("a good password", n=2**10)


def test_a_users_file_gives_each_user_a_role_keys_and_a_password():
    users = parse_users(
        f"users:\n"
        f"  ann:\n    role: student\n    keys:\n      - {PUB} ann@laptop\n"
        f"  ito:\n    role: instructor\n    password: {HASH}\n"
    )
    assert sorted(users) == ["ann", "ito"]
    ann, ito = users["ann"], users["ito"]
    assert (ann.role, ito.role) == ("student", "instructor")
    assert ann.accepts_key(KEY) and not ann.accepts_key(asyncssh.import_public_key(OTHER))
    assert not ann.accepts_password("a good password")  # ann has no password
    assert ito.accepts_password("a good password") and not ito.accepts_password("a bad one!")
    assert ito.keys == () and not ito.accepts_key(KEY)


def test_an_empty_or_missing_file_has_no_users(tmp_path):
    assert parse_users("") == {}
    assert parse_users("users:\n") == {}
    assert load_users(tmp_path / "nothing.yaml") == {}


@pytest.mark.parametrize(
    ("text", "line", "where", "fix"),
    [
        ("users:\n  ann:\n    role: teacher\n    password: X\n", 3, "users.ann.role", "student"),
        ("users:\n  ann:\n    keys: []\n", 2, "users.ann", "add 'role: student'"),
        (
            "users:\n  ann:\n    role: student\n    colour: red\n",
            4,
            "users.ann.colour",
            "role, keys and password",
        ),
        (
            "users:\n  ann:\n    role: student\n    keys:\n      - not-a-key AAAA\n",
            5,
            "users.ann.keys[1]",
            ".pub file",
        ),
        (
            "users:\n  ann:\n    role: student\n    password: hunter22\n",
            4,
            "users.ann.password",
            "workbench ssh add-user ann --password",
        ),
        ("users:\n  ann:\n    role: student\n", 2, "users.ann", "--key FILE.pub"),
        (
            "users:\n  ann:\n    role: student\n    keys: ssh-ed25519\n",
            4,
            "users.ann.keys",
            "'- ' line",
        ),
        ("users:\n  -bad:\n    role: student\n", 2, "users.-bad", "letters, digits"),
        ("people:\n  ann: {}\n", 1, "people", "'users:'"),
        ("users:\n  ann:\n    role: student\n  ann:\n    role: student\n", 4, "users", "twice"),
        ("users:\n  ann: [oops\n", 3, "YAML syntax", "docs/ssh.md"),
    ],
)
def test_a_malformed_file_names_the_line_the_key_and_the_fix(text, line, where, fix):
    with pytest.raises(UsersFileError) as caught:
        parse_users(text, "/srv/lab/ssh-users.yaml")
    problems = caught.value.problems
    assert any(
        (p.source, p.line) == ("/srv/lab/ssh-users.yaml", line)
        and where in p.message
        and fix in f"{p.message} {p.hint}"
        for p in problems
    ), problems
    assert str(caught.value) == "\n".join(str(p) for p in problems)


def test_every_user_with_a_problem_is_named_at_once_and_the_rest_are_not():
    text = (
        "users:\n  ann:\n    role: teacher\n    password: X\n"
        "  bo:\n    role: student\n    keys: []\n"
        f"  cy:\n    role: student\n    keys: [{PUB}]\n"
    )
    with pytest.raises(UsersFileError) as caught:
        parse_users(text, "users.yaml")
    found = [(p.line, p.message.split(":")[0]) for p in caught.value.problems]
    assert found == [(3, "users.ann.role"), (5, "users.bo")], found


def test_add_user_writes_a_file_only_its_owner_reads_and_updates_users(tmp_path):
    path = tmp_path / "ssh-users.yaml"
    add_user(path, "ann", "student", [PUB])
    assert stat.S_IMODE(os.stat(path).st_mode) == 0o600
    add_user(path, "ann", "student", [PUB, OTHER], HASH)  # the same key is not added twice
    add_user(path, "ito", "instructor", password_hash=HASH)
    users = load_users(path)
    assert users["ann"].keys == (PUB, OTHER) and users["ann"].password == HASH
    assert users["ito"].role == "instructor"
    assert path.read_text().startswith("# Users of the workbench SSH lab server.")
    with pytest.raises(UsersFileError, match="needs a key"):
        add_user(path, "bo", "student")
    with pytest.raises(UsersFileError, match="cannot be an SSH login name"):
        add_user(path, "bo b", "student", [PUB])


def test_the_server_reads_an_edited_file_again_and_keeps_the_old_users_if_it_is_broken(tmp_path):
    path = tmp_path / "ssh-users.yaml"
    add_user(path, "ann", "student", [PUB])
    users = UsersFile(path)
    assert users.get("ann") is not None and users.get("ben") is None
    add_user(path, "ben", "student", [OTHER])
    assert users.get("ben") is not None and users.problem == ""
    path.write_text("users:\n  ann:\n    role: wizard\n")
    assert users.get("ann") is not None  # the users read before stay in force
    assert "users.ann.role" in users.problem
