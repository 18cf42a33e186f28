"""What a session channel that asks for anything but a terminal running the workbench (or an
SFTP transfer) reads: one line, and exit status 1."""

from __future__ import annotations

NOT_A_TERMINAL = (
    "This lab server runs the workbench only, in a terminal: "
    "connect with plain 'ssh -p {port} {user}@{host}'."
)
#: what a session channel that asked for nothing within the grace reads as it is closed
ASKED_NOTHING = (
    "This lab server closed a channel that asked for nothing (no terminal, command or "
    "subsystem) within {grace:g} s."
)
NO_COMMANDS = "This lab server runs the workbench only: no commands ({what} refused)."
NO_FILES = "This lab server takes files by SFTP only ({what} refused)."
#: the old scp protocol runs a command on the server (``scp -t``/``scp -f``), which is not offered
OLD_SCP = (
    "This lab server takes files by SFTP only: the old scp protocol (scp -O) is not offered. "
    "Use 'scp -P {port} FILE {user}@{host}:' without -O (scp speaks SFTP by itself), or "
    "'sftp -P {port} {user}@{host}'."
)


def refusal_message(request: str, command: str, port: int, user: str, host: str) -> str:
    """The line for a refused ``request`` (``shell``, ``command '...'``, ``subsystem '...'``;
    ``command`` is the command asked for, if any)."""
    if request.startswith("subsystem"):
        return NO_FILES.format(what=request)
    words = command.split()
    if words[:1] == ["scp"] and ("-t" in words or "-f" in words):
        return OLD_SCP.format(port=port, user=user, host=host)
    if request.startswith("command"):
        return NO_COMMANDS.format(what=request)
    return NOT_A_TERMINAL.format(port=port, user=user, host=host)
