"""The one key table: every key a screen or dialog answers is in it, and every entry is used."""

from __future__ import annotations

import importlib
import pkgutil

import pytest
from textual.binding import Binding
from textual.dom import DOMNode

import workbench.tui
from workbench.tui.app import WorkbenchApp
from workbench.tui.keys import (
    EDITOR_LEGEND,
    HELP_SECTIONS,
    KEY_TABLE,
    PROGRAM_KEYS,
    REPLAY_LEGEND,
    LegendEntry,
    bindings,
    legend_text,
)
from workbench.tui.screens.editor import EditorScreen
from workbench.tui.screens.fsm_editor import FsmEditorScreen
from workbench.tui.screens.labs import LabsScreen
from workbench.tui.screens.main import MainScreen
from workbench.tui.screens.replay import ReplayScreen
from workbench.tui.screens.runs import RunsScreen


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
            assert binding.id in KEY_TABLE, (cls.__name__, binding)
            made = [(b.key, b.action) for b in bindings(binding.id)]
            assert (binding.key, binding.action) in made, cls.__name__
            used.add(binding.id)
    assert used == set(KEY_TABLE), f"entries no screen answers: {sorted(set(KEY_TABLE) - used)}"


def test_each_entry_explains_itself_in_a_sentence():
    for key_id, key in KEY_TABLE.items():
        assert key.title and key.label and key.explanation.endswith("."), key_id


def test_the_legends_beside_the_mazes_say_the_keys_their_screen_answers():
    for screen, legend in ((EditorScreen, EDITOR_LEGEND), (ReplayScreen, REPLAY_LEGEND)):
        answered = {b.id for b in declared(screen)}
        in_legend = {key_id for row in legend for entry in row for key_id in entry.ids}
        assert in_legend <= answered, screen.__name__
        footer = {key_id for key_id in answered if KEY_TABLE[key_id].show}
        assert footer <= in_legend, screen.__name__


def test_a_legend_writes_each_key_as_the_table_does():
    (save, save_as, leave), *_ = reversed(EDITOR_LEGEND)
    assert (save.text(), save_as.text(), leave.text()) == ("^s save", "a save as", "esc back")
    assert legend_text(EDITOR_LEGEND).splitlines()[-1] == "^s save  a save as  esc back"
    with pytest.raises(KeyError, match=r"editor\.nothing"):
        LegendEntry(("editor.nothing",))


def test_a_running_program_gets_the_letters_and_digits_the_main_screen_leaves_free():
    taken = {b.key for b in declared(MainScreen)}
    assert "w" not in PROGRAM_KEYS and "p" not in PROGRAM_KEYS and "R" not in PROGRAM_KEYS
    assert set("0123456789") <= PROGRAM_KEYS
    assert not PROGRAM_KEYS & taken
    assert PROGRAM_KEYS | taken >= set("abcdefghijklmnopqrstuvwxyz")


def test_the_help_explains_the_keys_each_screen_answers():
    for heading, ids in HELP_SECTIONS:
        screen = {
            "Workbench": MainScreen,
            "Labs (l)": LabsScreen,
            "Maze editor (e)": EditorScreen,
            "FSM editor (F)": FsmEditorScreen,
            "Runs (R)": RunsScreen,
            "Replay (enter on a run)": ReplayScreen,
        }[heading]
        answered = {b.id for b in declared(screen)}
        if heading == "Workbench":
            answered |= {b.id for b in declared(WorkbenchApp) if b.id}
        assert set(ids) == answered, heading
