"""What the browser door is started with: the options of ``workbench serve-web``."""

from __future__ import annotations

import socket
from dataclasses import dataclass, field
from pathlib import Path

from workbench.control.recording import RecordQuota
from workbench.door.appproc import AppEntry
from workbench.door.limits import SessionLimits
from workbench.door.logins import LoginPolicy
from workbench.door.networks import Network
from workbench.door.users import users_path
from workbench.files.workspace_files import UploadLimits


@dataclass
class WebConfig:
    data_dir: Path
    port: int = 8080
    bind: str = ""
    users_file: Path | None = None
    port_range: tuple[int, int] = (42000, 42999)
    public_host: str = ""
    limits: SessionLimits = field(default_factory=SessionLimits)
    logins: LoginPolicy = field(default_factory=LoginPolicy)
    #: the app's command before its settings, instead of the entry's (no fork server then)
    app_command: tuple[str, ...] | None = None
    fork_server: bool = True
    #: students' apps the fork server keeps started ahead of their sessions (0: none)
    spare_apps: int = 0
    stop_grace: float = 2.0
    #: seconds an app waits for its page to come back after the page's WebSocket closed
    reattach_grace: float = 60.0
    #: seconds a browser's login lasts
    login_lifetime: float = 12 * 3600.0
    #: TLS: the certificate chain and its key (PEM); without them plain HTTP (for a balancer or
    #: a proxy that does TLS in front)
    tls_cert: Path | None = None
    tls_key: Path | None = None
    #: the trusted-header mode: the header an authenticating proxy names the user in, and the
    #: proxies' addresses it is believed from (the header from anywhere else is refused)
    user_header: str = ""
    trusted_proxies: tuple[Network, ...] = ()
    #: the largest WebSocket message a page may send, in bytes (keys and sizes are small)
    max_message: int = 64 * 1024
    app: AppEntry = field(kw_only=True)
    record_quota: RecordQuota = field(default_factory=RecordQuota, kw_only=True)
    uploads: UploadLimits = field(default_factory=UploadLimits, kw_only=True)
    db: str | None = field(default=None, repr=False, kw_only=True)

    def __post_init__(self) -> None:
        self.data_dir = Path(self.data_dir)
        self.users_file = Path(self.users_file or users_path(self.data_dir))
        self.public_host = self.public_host or socket.getfqdn()

    @property
    def tls(self) -> bool:
        return self.tls_cert is not None
