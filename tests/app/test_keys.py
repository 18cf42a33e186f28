"""The one key table: every key a screen or dialog answers is in it, and every entry is used."""

from __future__ import annotations

import importlib
import pkgutil

from textual.binding import Binding
from textual.dom import DOMNode

import workbench.tui
from workbench.tui.keys import KEYS, bindings


def every_node_class() -> list[type[DOMNode]]:
    found: list[type[DOMNode]] = []
    for info in pkgutil.walk_packages(workbench.tui.__path__, "workbench.tui."):
        module = importlib.import_module(info.name)
        for value in vars(module).values():
            if (
                isinstance(value, type)
                and issubclass(value, DOMNode)
                and value.__module__ == module.__name__
            ):
                found.append(value)
    return found


def declared(cls: type[DOMNode]) -> list[Binding]:
    return [b for b in cls.__dict__.get("BINDINGS", []) if isinstance(b, Binding)]


def test_every_key_of_every_screen_and_dialog_comes_from_the_table():
    used: set[str] = set()
    for cls in every_node_class():
        for binding in declared(cls):
            if binding.action in ("focus_next", "focus_previous"):
                continue  # tab moves the focus everywhere; the help's Dialogs section says so
            assert binding.id in KEYS, (cls.__name__, binding)
            made = [(b.key, b.action) for b in bindings(binding.id)]
            assert (binding.key, binding.action) in made, cls.__name__
            used.add(binding.id)
    assert used == set(KEYS), f"entries no screen answers: {sorted(set(KEYS) - used)}"


def test_each_entry_explains_itself_in_a_sentence():
    for key_id, key in KEYS.items():
        assert key.title and key.label and key.explanation.endswith("."), key_id
