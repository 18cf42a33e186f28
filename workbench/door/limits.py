"""The server's limits on what one user may spend: sessions per user and in all, the idle
timeout, connections per user and channels per connection, the terminal's size and how often
it may change, each app's memory and the room its error log takes, and the server's own
memory."""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class SessionLimits:
    per_user: int = 2
    total: int = 60
    idle_timeout: float = 7200.0
    #: connections one user may hold logged in, with or without a session (forwarding-only
    #: ``ssh -N`` ones and lost ones not yet timed out count too)
    connections_per_user: int = 10
    #: the largest terminal an app is given, and how often a resize is passed on (seconds)
    max_columns: int = 500
    max_rows: int = 200
    resize_every: float = 0.1
    #: each app's memory, in MiB (0: no cap)
    app_memory: int = 512
    #: bytes of one session's error log, rotated once (so twice this on disk), and of all
    #: of one user's logs, the oldest removed at a session's start (0: no limit)
    app_log: int = 1_000_000
    user_logs: int = 20_000_000
    #: channels one connection may hold open at once: sessions (a terminal, a file transfer,
    #: or one refused and not yet closed) and forwards to a VIPLE port
    channels_per_connection: int = 10
    #: seconds a session channel has to ask for a terminal, a command or a subsystem before it
    #: is closed
    channel_grace: float = 10.0
    #: the server process's own memory, in MiB, past which it takes no new connections,
    #: channels or sessions (the live ones go on); 0: not watched
    server_memory: int = 1024

    def refusal(self, user_sessions: int, all_sessions: int) -> str | None:
        """The message for a user who would open one more session, or None when it may."""
        if all_sessions >= self.total:
            many = "session" if self.total == 1 else "sessions"
            return f"The lab server is full ({self.total} {many}); try again in a few minutes."
        if user_sessions >= self.per_user:
            many = "session" if self.per_user == 1 else "sessions"
            return (
                f"You already have {self.per_user} workbench {many} open, the most one "
                "user may have; quit one (ctrl+q) and try again."
            )
        return None

    def connection_refusal(self, user_connections: int) -> str | None:
        """The message for a user who would hold one more connection, or None when they may."""
        if user_connections < self.connections_per_user:
            return None
        many = "connection" if self.connections_per_user == 1 else "connections"
        return (
            f"You already have {self.connections_per_user} {many} to the lab server, the most "
            "one user may have: close the ones you do not use (lost ones end within a few "
            "minutes) and try again."
        )

    def channel_refusal(self, open_channels: int) -> str | None:
        """The reason given to a connection that would open one more channel, or None."""
        if open_channels < self.channels_per_connection:
            return None
        many = "channel" if self.channels_per_connection == 1 else "channels"
        return (
            f"this connection has {self.channels_per_connection} {many} open, the most one "
            "connection may have: close one, or open another connection"
        )

    def terminal_size(self, width: int, height: int) -> tuple[int, int]:
        """The size an app is given for a terminal of ``width`` x ``height``."""
        return min(width, self.max_columns), min(height, self.max_rows)

    def memory_message(self) -> str:
        share = describe_memory(self.app_memory)
        return (
            f"Your workbench used more than its share of memory ({share}) and was ended. "
            "Your lab progress is saved; log in again to go on."
        )


def describe_memory(mib: int) -> str:
    """``1024`` as ``"1 GiB"``, ``300`` as ``"300 MiB"``."""
    if mib >= 1024 and mib % 1024 == 0:
        return f"{mib // 1024} GiB"
    return f"{mib} MiB"


def describe_duration(seconds: float) -> str:
    """``7200`` as ``"2 h"``, ``90`` as ``"90 s"``: for the idle-timeout message."""
    if seconds >= 3600 and seconds % 3600 == 0:
        return f"{int(seconds // 3600)} h"
    if seconds >= 60 and seconds % 60 == 0:
        return f"{int(seconds // 60)} min"
    return f"{seconds:g} s"
