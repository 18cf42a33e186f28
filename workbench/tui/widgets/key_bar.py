"""The compact key bar at the foot of every screen: Textual's footer, showing the keys that
fit on one row, with each key made compact before it is first styled.

Where not every key fits, the keys of the lowest rank (``rank`` in ``tui/keys.py``) stay and
the others give way, in the screen's order: at 80 columns the main screen still shows the
labs, the editor, the runs, the maze and the help. The bar never draws one key over another,
and the command palette's key (which Textual docks at the right, over the others) is left to
the message line and the help.

Textual's footer styles every key as it mounts it and then again, for each key, when the key
takes the footer's ``compact`` setting and with it the ``-compact`` class: a third of the CPU
a served app spends before its first screen went on styling the footer's keys. Here the keys
carry the class from the start, so the second styling finds nothing to change.

While a dialog is open over the bar's screen, the bar shows the dialog's keys instead (and of
the app's keys only its priority ones, such as ``^q``, which reach it past a dialog): the
screen's own keys do nothing then, so they are not shown.
"""

from __future__ import annotations

from collections.abc import Sequence

from textual import events
from textual.app import ComposeResult
from textual.widgets import Footer

from ..keys import KEY_TABLE
from ..textual_private import FooterKey, bindings_of, footer_ready
from .under_dialog import DialogWatch

#: the rank of a key that is not in the workbench's table (Textual's own)
DEFAULT_RANK = 2


def key_width(key: FooterKey) -> int:
    """The columns a compact key takes: its key, a space, its label and the gap after it."""
    label = len(key.description) + 1 if key.description else 0
    return len(key.key_display) + label + 1


def fitting(widths: Sequence[int], ranks: Sequence[int], width: int) -> list[int]:
    """The indexes of the keys shown in ``width`` columns, in their order: the lowest ranks
    first (and within a rank the earlier keys), each while it still fits."""
    room = width + 1  # the last key needs no gap after it
    chosen: list[int] = []
    for i in sorted(range(len(widths)), key=lambda i: (ranks[i], i)):
        if widths[i] <= room:
            chosen.append(i)
            room -= widths[i]
    return sorted(chosen)


class KeyBar(Footer):
    """A compact footer of the screen's keys that fit (without the command palette's key)."""

    def __init__(self, *, id: str | None = None, classes: str | None = None) -> None:
        super().__init__(id=id, classes=classes, compact=True, show_command_palette=False)
        #: the keys shown, as (key, action) pairs, and the width they were chosen for
        self._shown: tuple[tuple[str, str], ...] = ()
        #: the dialog open over the bar's screen, whose keys the bar shows then
        self._under = DialogWatch(self, lambda: self.call_after_refresh(self.recompose), keys=True)

    def on_mount(self) -> None:
        self._under.start()

    def on_unmount(self) -> None:
        self._under.stop()

    def _keys(self) -> list[FooterKey]:
        """Every key the bar could show now, in order."""
        dialog = self._under.dialog
        if dialog is None:
            return [w for w in super().compose() if isinstance(w, FooterKey)]
        keys: list[FooterKey] = []
        actions: set[str] = set()
        app_keys = [
            (self.app, binding, True, binding.tooltip)
            for _key, binding in bindings_of(self.app)
            if binding.priority  # the app's other keys do not reach it past a dialog
        ]
        for _node, binding, enabled, tooltip in [*dialog.active_bindings.values(), *app_keys]:
            if not binding.show or binding.action in actions:
                continue
            actions.add(binding.action)
            key = FooterKey(
                binding.key,
                self.app.get_key_display(binding),
                binding.description,
                binding.action,
                disabled=not enabled,
                tooltip=tooltip,
            )
            keys.append(key)
        return keys

    def _width(self) -> int:
        return self.size.width or self.app.size.width

    def _ranks(self) -> dict[str, int]:
        """Each action's rank, from the workbench's key table."""
        ranks = {}
        screen = self._under.dialog or self.screen
        for _node, binding, _enabled, _tooltip in screen.active_bindings.values():
            key = KEY_TABLE.get(binding.id or "")
            ranks[binding.action] = key.rank if key is not None else DEFAULT_RANK
        return ranks

    def _choose(self, keys: list[FooterKey]) -> list[FooterKey]:
        ranks = self._ranks()
        order = [ranks.get(k.action, DEFAULT_RANK) for k in keys]
        shown = fitting([key_width(k) for k in keys], order, self._width())
        return [keys[i] for i in shown]

    def compose(self) -> ComposeResult:
        keys = self._keys()
        chosen = self._choose(keys)
        self._shown = tuple((k.key, k.action) for k in chosen)
        for widget in chosen:
            widget.set_class(True, "-compact", update=False)
            yield widget

    def on_resize(self, event: events.Resize) -> None:
        if not footer_ready(self):
            return
        keys = self._keys()
        if tuple((k.key, k.action) for k in self._choose(keys)) != self._shown:
            self.call_after_refresh(self.recompose)
