"""The command palette: the keys of the screen it was opened on (and the app's) as commands,
named and explained by the one key table, :data:`~workbench.tui.keys.KEY_TABLE`; a key its
screen hides (``check_action`` says False) is not offered."""

from __future__ import annotations

from collections.abc import Awaitable, Callable, Iterator
from functools import partial

from textual.actions import parse
from textual.binding import Binding
from textual.command import DiscoveryHit, Hit, Hits, Provider
from textual.dom import DOMNode

from .keys import KEY_TABLE
from .textual_private import bindings_of


def key_display(node: DOMNode, binding: Binding) -> str:
    """How the key is written on screen (``spc`` -> ``space``, ``ctrl+q`` -> ``^q``)."""
    if binding.key_display:
        return binding.key_display
    return node.app.get_key_display(binding)


def bindings_with_ids(node: DOMNode) -> Iterator[Binding]:
    """The node's bindings that have an id, once each, in declared order."""
    seen: set[str] = set()
    for _key, binding in bindings_of(node):
        if binding.id and binding.id not in seen and binding.id in KEY_TABLE:
            seen.add(binding.id)
            yield binding


class WorkbenchCommands(Provider):
    """The key bindings of the current screen and of the app as command palette commands."""

    def _commands(self) -> list[tuple[str, str, Callable[[], Awaitable[object]]]]:
        out: list[tuple[str, str, Callable[[], Awaitable[object]]]] = []
        seen: set[str] = set()
        for node in (self.screen, self.app):
            for binding in bindings_with_ids(node):
                assert binding.id is not None
                if binding.id in seen or binding.id == "app.commands":
                    continue
                seen.add(binding.id)
                _namespace, name, params = parse(binding.action)
                if node.check_action(name, params) is False:
                    continue  # a key the screen hides now does nothing now
                info = KEY_TABLE[binding.id]
                title = f"{info.group}: {info.title}"
                help_text = f"key {key_display(node, binding)}: {info.explanation}"
                out.append((title, help_text, partial(self.app.run_action, binding.action, node)))
        return out

    async def discover(self) -> Hits:
        for title, help_text, run in self._commands():
            yield DiscoveryHit(title, run, help=help_text)

    async def search(self, query: str) -> Hits:
        matcher = self.matcher(query)
        for title, help_text, run in self._commands():
            score = matcher.match(title)
            if score > 0:
                yield Hit(score, matcher.highlight(title), run, help=help_text)
