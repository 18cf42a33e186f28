"""The server's session limits: sessions per user and in all, and the idle timeout."""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class SessionLimits:
    per_user: int = 2
    total: int = 60
    idle_timeout: float = 7200.0

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


def describe_duration(seconds: float) -> str:
    """``7200`` as ``"2 h"``, ``90`` as ``"90 s"``: for the idle-timeout message."""
    if seconds >= 3600 and seconds % 3600 == 0:
        return f"{int(seconds // 3600)} h"
    if seconds >= 60 and seconds % 60 == 0:
        return f"{int(seconds // 60)} min"
    return f"{seconds:g} s"
