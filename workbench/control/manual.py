"""Drive-by-wire: the course's key programs (w / a / s / d / space) for each profile.

* unity: the Unity key program: w Move at Power 1, s Move at Power -1, a Turn by Degree -90,
  d Turn by Degree 90, space Move at Power 0.
* web: Robot Drive wheel powers as in the Web Simulator programs: w forward (0.5, 0.5),
  s backward (-0.3, -0.3), a spin left (-0.2, 0.2) and d spin right (0.2, -0.2) until the next
  key, space (0, 0).
* erobotic: exact moves: w / s drive exactly one block forward / back and stop, a / d turn
  exactly 90 degrees, space stops.
"""

from __future__ import annotations

from workbench.sim.commands import Command, MoveAtPower, Stop, TurnByDegrees, WheelPowers

DRIVE_KEYS = ("w", "a", "s", "d", "space")
KEY_NAMES = {
    "w": "forward",
    "a": "left",
    "s": "backward",
    "d": "right",
    "space": "stop",
}

_UNITY: dict[str, Command] = {
    "w": MoveAtPower(1.0),
    "s": MoveAtPower(-1.0),
    "a": TurnByDegrees(-90),
    "d": TurnByDegrees(90),
    "space": MoveAtPower(0.0),
}
_WEB: dict[str, Command] = {
    "w": WheelPowers(0.5, 0.5),
    "s": WheelPowers(-0.3, -0.3),
    "a": WheelPowers(-0.2, 0.2),
    "d": WheelPowers(0.2, -0.2),
    "space": WheelPowers(0.0, 0.0),
}
_EROBOTIC: dict[str, Command] = {
    "w": MoveAtPower(1.0),
    "s": MoveAtPower(-1.0),
    "a": TurnByDegrees(-90),
    "d": TurnByDegrees(90),
    "space": Stop(),
}
KEY_PROGRAMS = {"unity": _UNITY, "web": _WEB, "erobotic": _EROBOTIC}


def key_legend(profile: str) -> list[tuple[str, str]]:
    """(key, what it does) for the key legend of ``profile``."""
    detail = {
        "unity": {"w": "Move at Power 1", "s": "Move at Power -1", "a": "Turn -90",
                  "d": "Turn 90", "space": "Power 0"},
        "web": {"w": "Drive 0.5 0.5", "s": "Drive -0.3 -0.3", "a": "spin left",
                "d": "spin right", "space": "Drive 0 0"},
        "erobotic": {"w": "one block", "s": "one block back", "a": "turn 90 left",
                     "d": "turn 90 right", "space": "stop"},
    }[profile]  # fmt: skip
    return [(k, f"{KEY_NAMES[k]} ({detail[k]})") for k in DRIVE_KEYS]


def key_command(profile: str, key: str) -> Command | None:
    """The command ``key`` gives in ``profile``'s key program (None for other keys)."""
    try:
        return KEY_PROGRAMS[profile].get(key)
    except KeyError:
        raise ValueError(f"no key program for profile {profile!r}") from None


def exact_move(profile: str, key: str) -> bool:
    """True when ``key`` is a one-block move that must stop by itself (erobotic w / s)."""
    return profile == "erobotic" and key in ("w", "s")
