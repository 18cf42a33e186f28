"""VIPLE's key numbers (Key Press Event values) and scripts of key presses for headless runs.

A Key Press Event stores an index into VIPLE's key list: ``a``..``z`` are 0..25, the digits
``0``..``9`` are taken to be 26..35, ``up`` 36, ``left`` 37, ``right`` 38, ``down`` 39 and
``space`` 59.

A key script says what a student would press and when, in simulated seconds:
``"w@0.5 release@3.0 a+d@4.2"``. Pressing a key holds it down with any key already held;
``release`` lets go of every key, which is when VIPLE's Key Release Event fires (a terminal
sends no key-up, so in a script and in the app a release is always explicit).
"""

from __future__ import annotations

import math
import string
from dataclasses import dataclass

KEY_NAMES: dict[int, str] = {i: ch for i, ch in enumerate(string.ascii_lowercase)}
KEY_NAMES.update({26 + d: str(d) for d in range(10)})
KEY_NAMES.update({36: "up", 37: "left", 38: "right", 39: "down", 59: "space"})
KEY_NUMBERS = {name: number for number, name in KEY_NAMES.items()}
MAX_KEY_EVENTS = 10_000
RELEASE = "release"


class KeyScriptError(ValueError):
    """A key script that cannot be read, naming the item and the fix."""


@dataclass(frozen=True)
class KeyEvent:
    time: float
    #: the keys pressed; empty for a release of the whole keyboard
    keys: frozenset[str]

    @property
    def release(self) -> bool:
        return not self.keys


def parse_key_script(text: str) -> tuple[KeyEvent, ...]:
    items = text.split()
    if len(items) > MAX_KEY_EVENTS:
        raise KeyScriptError(f"more than {MAX_KEY_EVENTS:,} key events")
    events = []
    for number, item in enumerate(items, 1):
        keys, sep, when = item.partition("@")
        where = f"key {number} {item[:30]!r}"
        if not sep:
            raise KeyScriptError(f"{where} must be KEY@SECONDS, e.g. w@0.5 or release@3")
        try:
            time = float(when)
        except ValueError:
            raise KeyScriptError(f"{where}: {when[:20]!r} is not a number of seconds") from None
        if not math.isfinite(time) or time < 0:
            raise KeyScriptError(f"{where}: the time must be 0 or more seconds")
        if keys.lower() == RELEASE:
            events.append(KeyEvent(time, frozenset()))
            continue
        names = [k.lower() for k in keys.split("+")]
        for name in names:
            if name not in KEY_NUMBERS:
                raise KeyScriptError(
                    f"{where}: {name[:20]!r} is not a key: use a-z, 0-9, up, down, left, "
                    "right, space or release"
                )
        events.append(KeyEvent(time, frozenset(names)))
    return tuple(sorted(events, key=lambda e: e.time))
