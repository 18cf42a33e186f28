"""Who may log in to the lab server: the users file, read with line numbers for clear errors.

The file (YAML, written by ``workbench ssh add-user``)::

    users:
      alice:
        role: student                 # or instructor
        keys:                         # authorized OpenSSH public keys, one a line
          - ssh-ed25519 AAAAC3Nz... alice@laptop
        password: scrypt$16384$8$1$...  # a hash made by add-user, never the password

Every problem names the file, the line, the key and the fix; the server does not start with a
file it cannot read.
"""

from __future__ import annotations

import os
import re
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path

import asyncssh
import yaml

from workbench.files.atomic import write_text_atomic
from workbench.files.bounded import (
    USERS_LIMITS,
    BoundedFileError,
    check_text,
    compose_yaml,
    read_text,
)
from workbench.files.problems import Problem
from workbench.files.yamlread import (
    NodeReader,
    Skip,
    is_null,
    problem_list,
    refused_problem,
    syntax_problem,
)

from .passwords import PasswordError, parse_hash, verify_password

ROLES = ("student", "instructor")
USERS_FILE = "ssh-users.yaml"
NAME_PATTERN = re.compile(r"[A-Za-z0-9_][A-Za-z0-9_.-]{0,31}")
FIELDS = ("role", "keys", "password")
HEADER = (
    "# Users of the workbench SSH lab server.\n"
    "# Change it with: workbench ssh add-user NAME --role student|instructor "
    "[--key FILE.pub] [--password]\n"
)


class UsersFileError(ValueError):
    """A users file (or a user to add) that cannot be used; for a file, ``problems`` lists
    every problem found, each as ``file:line:column: where: what (hint: fix)``."""

    def __init__(self, message: str, problems: Sequence[Problem] = ()) -> None:
        super().__init__(message)
        self.problems = list(problems)

    @classmethod
    def found(cls, problems: Sequence[Problem]) -> UsersFileError:
        problems = problem_list(problems)
        return cls("\n".join(str(p) for p in problems), problems)


def users_path(data_dir: str | os.PathLike) -> Path:
    """The users file of a data folder."""
    return Path(data_dir) / USERS_FILE


def check_user_name(name: str) -> str:
    if not NAME_PATTERN.fullmatch(name):
        raise UsersFileError(
            f"{name!r} cannot be an SSH login name: use 1-32 letters, digits, '_', '.' or '-', "
            "not starting with '.' or '-'"
        )
    return name


def parse_public_key(text: str) -> asyncssh.SSHKey:
    """One OpenSSH public key line (``type base64 [comment]``); ValueError says what is wrong."""
    text = text.strip()
    if not text or text.startswith("#"):
        raise ValueError("an empty key")
    try:
        return asyncssh.import_public_key(text)
    except (asyncssh.KeyImportError, ValueError) as exc:
        raise ValueError(f"not an OpenSSH public key ({exc})") from None


@dataclass(frozen=True)
class User:
    name: str
    role: str
    keys: tuple[str, ...] = ()
    password: str | None = None
    _public: tuple[bytes, ...] = field(default=(), compare=False, repr=False)

    def with_keys(self) -> User:
        """The user with its keys parsed once (for quick checks at login)."""
        blobs = tuple(parse_public_key(k).public_data for k in self.keys)
        return replace(self, _public=blobs)

    def accepts_key(self, key: asyncssh.SSHKey) -> bool:
        blobs = self._public or tuple(parse_public_key(k).public_data for k in self.keys)
        return key.public_data in blobs

    def accepts_password(self, password: str) -> bool:
        return self.password is not None and verify_password(password, self.password)

    def fingerprints(self) -> list[str]:
        return [parse_public_key(k).get_fingerprint() for k in self.keys]


def parse_users(text: str, path: str | os.PathLike = USERS_FILE) -> dict[str, User]:
    """The users of a users file's text; :class:`UsersFileError` lists every problem with its
    line, key and fix."""
    try:
        root = compose_yaml(check_text(text, str(path), USERS_LIMITS), str(path), USERS_LIMITS)
    except BoundedFileError as exc:
        raise _refused(exc) from None
    except yaml.YAMLError as exc:
        raise UsersFileError.found(
            [syntax_problem(str(path), exc, "compare with docs/ssh.md")]
        ) from None
    if root is None:
        return {}
    reader = NodeReader(str(path))
    users: dict[str, User] = {}
    try:
        node = _users_node(reader, root)
        for name, name_node, entry in reader.pairs(node, "users", "a mapping of login names"):
            try:
                users[name] = _user(reader, name, name_node, entry)
            except Skip:
                continue
    except Skip:
        pass
    reader.check(UsersFileError.found)
    return users


def _users_node(reader: NodeReader, root: yaml.Node) -> yaml.Node:
    top = reader.pairs(root, "", "a 'users:' mapping")
    for name, key, _ in top:
        if name != "users":
            reader.note(key, name, "is not a known key", "the file has one key, 'users:'")
    node = next((value for name, _, value in top if name == "users"), None)
    if is_null(node):
        raise Skip  # no users yet
    assert node is not None
    return node


def _user(reader: NodeReader, name: str, name_node: yaml.Node, entry: yaml.Node) -> User:
    where = f"users.{name}"
    if not NAME_PATTERN.fullmatch(name):
        reader.note(
            name_node,
            where,
            "is not a usable login name",
            "use 1-32 letters, digits, '_', '.' or '-'",
        )
    fields: dict[str, yaml.Node] = {}
    for key, _, value in reader.pairs(entry, where, "role, keys and/or password"):
        if key not in FIELDS:
            reader.note(
                value, f"{where}.{key}", "is not a known key", "use role, keys and password only"
            )
        else:
            fields[key] = value
    if "role" not in fields:
        reader.fail(name_node, where, "has no role", "add 'role: student' or 'role: instructor'")
    role = reader.choice(fields["role"], f"{where}.role", ROLES, "role")
    before = len(reader.problems)
    keys = _keys(reader, fields.get("keys"), f"{where}.keys")
    password = None
    if "password" in fields:
        password = reader.text(
            fields["password"],
            f"{where}.password",
            f"make one with: workbench ssh add-user {name} --password",
        )
        try:
            parse_hash(password)
        except PasswordError as exc:
            reader.note(
                fields["password"],
                f"{where}.password",
                str(exc),
                f"set it again with: workbench ssh add-user {name} --password",
            )
    if not keys and password is None and len(reader.problems) == before:
        reader.note(
            name_node,
            where,
            "has neither keys nor a password, so cannot log in",
            f"workbench ssh add-user {name} --key FILE.pub (or --password)",
        )
    return User(name, role, keys, password)


def _keys(reader: NodeReader, node: yaml.Node | None, where: str) -> tuple[str, ...]:
    if is_null(node) or (isinstance(node, yaml.SequenceNode) and not node.value):
        return ()
    if not isinstance(node, yaml.SequenceNode):
        reader.fail(node, where, "must be a list", "write each key on its own '- ' line")
    keys: list[str] = []
    for index, item in enumerate(node.value, 1):
        text = reader.text(item, f"{where}[{index}]", "paste one line of the user's .pub file")
        try:
            parse_public_key(text)
        except ValueError as exc:
            reader.note(
                item,
                f"{where}[{index}]",
                str(exc),
                "paste the whole line of the user's .pub file (e.g. ~/.ssh/id_ed25519.pub)",
            )
            continue
        keys.append(text)
    return tuple(keys)


def load_users(path: str | os.PathLike) -> dict[str, User]:
    """The users of the file at ``path`` (none when it does not exist)."""
    path = Path(path)
    if not path.exists():
        return {}
    try:
        text = read_text(path, USERS_LIMITS)
    except BoundedFileError as exc:
        raise _refused(exc) from None
    return {name: user.with_keys() for name, user in parse_users(text, path).items()}


def _refused(exc: BoundedFileError) -> UsersFileError:
    """The error of a users file refused by the bounded reader."""
    return UsersFileError.found([refused_problem(exc)])


def dump_users(users: Iterable[User]) -> str:
    """The text of a users file holding ``users`` (sorted by name)."""
    entries: dict[str, dict[str, object]] = {}
    for user in sorted(users, key=lambda u: u.name):
        entry: dict[str, object] = {"role": user.role}
        if user.keys:
            entry["keys"] = list(user.keys)
        if user.password:
            entry["password"] = user.password
        entries[user.name] = entry
    body = yaml.safe_dump({"users": entries}, sort_keys=False, width=10_000)
    return HEADER + body


def save_users(path: str | os.PathLike, users: Iterable[User]) -> None:
    """Write the users file in one step, readable by its owner only (it holds hashes)."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    write_text_atomic(path, dump_users(users), mode=0o600)


def add_user(
    path: str | os.PathLike,
    name: str,
    role: str,
    keys: Iterable[str] = (),
    password_hash: str | None = None,
) -> User:
    """Create or update one user (keys are added, a password replaces the old one)."""
    check_user_name(name)
    if role not in ROLES:
        raise UsersFileError(f"{role!r} is not a role: use student or instructor")
    users = load_users(path)
    old = users.get(name)
    have = list(old.keys) if old else []
    blobs = {parse_public_key(k).public_data for k in have}
    for text in keys:
        key = parse_public_key(text)
        if key.public_data not in blobs:
            blobs.add(key.public_data)
            have.append(text.strip())
    password = password_hash or (old.password if old else None)
    if not have and not password:
        raise UsersFileError(f"{name} needs a key (--key FILE.pub) or a password (--password)")
    user = User(name, role, tuple(have), password)
    users[name] = user
    save_users(path, users.values())
    return user


class UsersFile:
    """The users file as the server reads it: read again when it changes on disk.

    A broken edit while the server runs is logged and the users read before stay in force.
    """

    def __init__(self, path: str | os.PathLike) -> None:
        self.path = Path(path)
        self._stamp = self._stat()
        self.users = load_users(self.path)
        self.problem = ""

    def _stat(self) -> tuple[int, int] | None:
        try:
            st = self.path.stat()
        except OSError:
            return None
        return st.st_mtime_ns, st.st_size

    def get(self, name: str) -> User | None:
        stamp = self._stat()
        if stamp != self._stamp:
            self._stamp = stamp
            try:
                self.users = load_users(self.path)
                self.problem = ""
            except UsersFileError as exc:
                self.problem = str(exc)
        return self.users.get(name)
