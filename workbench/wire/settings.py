"""What the workbench app is started with: one value from the command line (or the lab server)
to the app.

The command line builds :class:`AppSettings` from its options (``workbench/cli/__init__.py``);
the SSH lab server builds one for each session (``workbench/door/appproc.py``) and hands it to the
session's app as a JSON object (:meth:`AppSettings.to_json`), through the fork server or on the
command line of a new process, and the app reads it back with :meth:`AppSettings.from_json`.
:func:`workbench.tui.app.make_app` takes it and checks what only the app can check (the maze
file, the names, the profile and noise level).

It is part of the wire (``workbench/wire/``), which imports no Textual (an import-linter
contract keeps it so): the lab server reads it without importing the app.
"""

from __future__ import annotations

import os
import types
from dataclasses import dataclass, field, fields
from pathlib import Path
from typing import Any, Union, get_args, get_origin, get_type_hints

from workbench.control.recording import RECORD_CAP, RUNS_QUOTA, RecordQuota
from workbench.files.workspace_files import UploadLimits

#: the settings that are each served session's own (who, their ports and folders): a spare app
#: (``workbench/door/spares.py``) starts without them and takes them from its session
SESSION_FIELDS = frozenset(
    {"student", "partner", "tcp_port", "ws_url", "connect_hint", "record_dir", "runs_counted",
     "workspace"}
)  # fmt: skip


class SettingsError(ValueError):
    """Settings that are not the app's (an unknown name, a value of the wrong kind)."""


@dataclass(frozen=True)
class AppSettings:
    """The workbench app's settings; every one has the default the command line gives."""

    #: the maze file to open (None: the bundled Unity maze)
    maze_path: Path | None = None
    #: the robot's profile, unity, web or erobotic (None: the maze file's own)
    profile: str | None = None
    #: the sensor noise's seed
    seed: int = 0
    #: off, low or realistic (None: the profile's)
    noise: str | None = None
    #: the simulation starts paused
    paused: bool = False
    #: the app's clock ticks this often a second while anything moves
    tick_hz: float = 20.0
    #: how often a VIPLE program file driving the robot gets its sensor reports, milliseconds
    #: (None: the profile's simulator period, 250 ms)
    report_ms: int | None = None
    #: draw with Unicode lines, arrows and marks (False: plain ASCII)
    unicode: bool = False
    #: where each run's record is kept for replay (None: no records)
    record_dir: Path | None = None
    #: the largest one run record may grow, in bytes (None: no limit)
    record_cap: int | None = RECORD_CAP
    #: the most all run records in :attr:`runs_counted` may take, in bytes (None: no limit)
    runs_quota: int | None = RUNS_QUOTA
    #: the folder the runs quota counts (a served student's ``~/runs``; None: the record
    #: folder)
    runs_counted: Path | None = None
    #: the TCP port VIPLE connects to, the Unity-simulator role (None: not served at start)
    tcp_port: int | None = None
    #: the VIPLE WebSocket server the app connects to, the Web-Simulator role (None: none)
    ws_url: str | None = None
    #: connect to ``ws_url`` from the start (False: once a WebSocket exercise is set up or the
    #: student presses v)
    ws_at_start: bool = True
    #: who does the labs (None: the pair last at this workbench, else the login name)
    student: str | None = None
    #: the student's lab partner
    partner: str = ""
    #: shown beside the names: student or instructor
    role: str = "student"
    #: where lab progress and sign-offs are kept (None: $WORKBENCH_DATA or the user data folder)
    data_dir: Path | None = None
    #: ask for the names when the app starts
    ask_names: bool = False
    #: the student's name cannot be changed in the names dialog (an SSH login's)
    student_fixed: bool = False
    #: how VIPLE reaches this app from elsewhere, shown at start and in the help
    connect_hint: str = ""
    #: the only folder the app opens and saves files in, besides the bundled ones (a served
    #: student's; None: anywhere)
    workspace: Path | None = None
    #: what the app may keep in :attr:`workspace`, as the file server allows a student (each
    #: 0: no limit): the largest file, all the student's files, how many files and folders
    upload_cap: int = 0
    workspace_quota: int = 0
    workspace_files: int = 0
    #: the course's PostgreSQL database URL (None: the SQLite file in the data folder); it may
    #: hold a password, so it is never shown and never sent with the rest
    db: str | None = field(default=None, repr=False)

    def __post_init__(self) -> None:
        # a folder or file given as text (a test, a script) is kept as a Path, as the
        # command line and the lab server give it
        for name in _PATHS:
            value = getattr(self, name)
            if value is not None and not isinstance(value, Path):
                object.__setattr__(self, name, Path(os.fspath(value)))

    def to_json(self) -> dict[str, Any]:
        """The settings as a JSON object (paths as text), without the database URL: an app
        started from them finds that in its environment (``$WORKBENCH_DB``)."""
        return {
            f.name: str(value) if isinstance(value, Path) else value
            for f in fields(self)
            if f.name != "db" and (value := getattr(self, f.name)) != f.default
        }

    @classmethod
    def from_json(cls, data: object) -> AppSettings:
        """Settings from a JSON object as :meth:`to_json` makes it (a setting left out keeps
        its default); :class:`SettingsError` names the first setting that is not the app's."""
        if not isinstance(data, dict):
            raise SettingsError(
                f"the app's settings must be a JSON object, not {type(data).__name__}"
            )
        kinds = _kinds()
        values: dict[str, Any] = {}
        for name, value in data.items():
            if name not in kinds or name == "db":
                raise SettingsError(
                    f"unknown setting {str(name)[:40]!r}: the app's settings are "
                    f"{', '.join(n for n in kinds if n != 'db')}"
                )
            values[name] = _read(name, kinds[name], value)
        return cls(**values)

    @property
    def uploads(self) -> UploadLimits | None:
        """What the app may keep in its workspace (None: no limit)."""
        if not (self.upload_cap or self.workspace_quota or self.workspace_files):
            return None
        return UploadLimits(self.upload_cap, self.workspace_quota, self.workspace_files)

    @property
    def record_quota(self) -> RecordQuota:
        """How much room the app's run records may take."""
        counted = str(self.runs_counted) if self.runs_counted is not None else None
        return RecordQuota(self.record_cap, self.runs_quota, counted)


#: the settings that name a file or folder
_PATHS = ("maze_path", "record_dir", "runs_counted", "data_dir", "workspace")
#: each kind of setting as the JSON it takes
_WORDS: dict[type, str] = {
    str: "text",
    Path: "text",
    int: "a whole number",
    float: "a number",
    bool: "true or false",
    type(None): "null",
}


def _kinds() -> dict[str, tuple[type, ...]]:
    """Each setting's accepted types, from its annotation."""
    kinds = {}
    for name, hint in get_type_hints(AppSettings).items():
        union = get_origin(hint) in (Union, types.UnionType)
        kinds[name] = get_args(hint) if union else (hint,)
    return kinds


def _read(name: str, kinds: tuple[type, ...], value: object) -> object:
    """``value`` as setting ``name`` takes it; SettingsError when it is of another kind."""
    if value is None and type(None) in kinds:
        return None
    if isinstance(value, bool):
        if bool in kinds:
            return value
    elif isinstance(value, str) and (str in kinds or Path in kinds):
        return Path(value) if Path in kinds else value
    elif isinstance(value, int) and int in kinds:
        return value
    elif isinstance(value, (int, float)) and float in kinds:
        return float(value)
    wanted = " or ".join(dict.fromkeys(_WORDS[k] for k in kinds))
    raise SettingsError(f"setting {name!r} must be {wanted}, not {value!r:.60}")
