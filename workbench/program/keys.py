"""VIPLE's key numbers (Key Press Event values) and scripts of key presses for headless runs.

A Key Press Event stores an index into VIPLE's key list: ``a``..``z`` are 0..25, the digits
``0``..``9`` are taken to be 26..35, ``up`` 36, ``left`` 37, ``right`` 38, ``down`` 39 and
``space`` 59.

A key script says what a student would press and when, in simulated seconds:
``"w@0.5 release@3.0 a+d@4.2"``. Pressing a key holds it down with any key already held;
``release`` lets go of every key, which is when VIPLE's Key Release Event fires.

A terminal sends no key-up: a key held down arrives as the same key again and again (the
keyboard's auto-repeat). :class:`TypedKeys` turns such presses into presses and releases by
one rule, the same in the app, in a headless run's ``--typed`` script and at the live keyboard
of ``viple run --connect``: a key counts as held while it keeps arriving; the keyboard is
released when no key has come for :data:`RELEASE_GAP` seconds, or when a different key arrives
(released first, then pressed). The seconds are those of the clock the caller passes in:
simulated time in the app and in headless runs, the wall clock when a program drives a real
robot, which runs in real time.
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
#: seconds without a key after which a typed key counts as released: longer than a keyboard's
#: delay before auto-repeat starts (0.25 to 0.66 s), so a held key stays held
RELEASE_GAP = 0.75


def known_key(name: str) -> str | None:
    """A key as a terminal or the app names it (``W``, `` ``, ``space``, ``up``) as VIPLE's
    key name (``w``, ``space``, ``up``); None for a key VIPLE has no number for. A capital
    letter is its letter: Shift is not a key of its own."""
    if name == " ":
        name = "space"
    if len(name) == 1:
        name = name.lower()
    return name if name in KEY_NUMBERS else None


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


class TypedKeys:
    """Key presses from a terminal (no key-up) as the presses and releases a program sees.

    It keeps no clock of its own: every call says the time ``t`` on the caller's clock."""

    def __init__(self, gap: float = RELEASE_GAP) -> None:
        self.gap = gap
        self.held: frozenset[str] = frozenset()
        self._last = 0.0

    def press(self, key: str, t: float) -> list[KeyEvent]:
        """``key`` arrived at ``t``: the events it makes (none for a repeat of the held key)."""
        events = [e for e in (self.due(t),) if e is not None]
        if key in self.held:
            self._last = t
            return events
        if self.held:
            events.append(KeyEvent(t, frozenset()))
        self.held = frozenset((key,))
        self._last = t
        events.append(KeyEvent(t, self.held))
        return events

    def due(self, t: float) -> KeyEvent | None:
        """The release the quiet gap makes by ``t`` (None while a key is still held)."""
        if not self.held or t < self._last + self.gap - 1e-9:
            return None
        self.held = frozenset()
        return KeyEvent(self._last + self.gap, frozenset())


def typed_events(script: tuple[KeyEvent, ...], until: float) -> tuple[KeyEvent, ...]:
    """A script of typed keys (``w@0.5 w@0.55 d@2``, one key an item, no releases) as the
    presses and releases :class:`TypedKeys` makes of it by ``until``."""
    typed = TypedKeys()
    out: list[KeyEvent] = []
    for event in script:
        if event.release or len(event.keys) != 1:
            raise KeyScriptError(
                f"typed keys at {event.time:g} s: type one key an item (releases come by "
                f"themselves after {RELEASE_GAP:g} s without a key)"
            )
        out += typed.press(next(iter(event.keys)), event.time)
    last = typed.due(until)
    if last is not None:
        out.append(last)
    return tuple(out)
