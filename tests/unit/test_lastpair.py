"""The last pair at a workbench, and names matched however they are cased and spaced."""

from __future__ import annotations

from workbench.labs.lastpair import FILE_NAME, read_last_pair, save_last_pair
from workbench.labs.names import name_key
from workbench.labs.store.store import Store


def test_the_last_pair_is_read_back(tmp_path):
    assert read_last_pair(tmp_path) is None
    save_last_pair(tmp_path, "Alice Doe", "Bo Li")
    assert read_last_pair(tmp_path) == ("Alice Doe", "Bo Li")
    save_last_pair(tmp_path, "Chen Wu")
    assert read_last_pair(tmp_path) == ("Chen Wu", "")


def test_a_damaged_or_hostile_file_is_ignored(tmp_path):
    path = tmp_path / FILE_NAME
    for text in ("{", "[]", '{"partner": "x"}', '{"student": "a\u200bb"}', "x" * 5000):
        path.write_text(text)
        assert read_last_pair(tmp_path) is None, text


def test_names_match_without_case_or_spacing():
    assert name_key("  alice   DOE ") == name_key("Alice Doe")
    assert name_key("Alice Doe") != name_key("Alice Dole")


def test_the_store_spells_a_known_student_as_it_was_saved(tmp_path):
    with Store.open(tmp_path) as store:
        store.progress.save("Alice Doe", "lab", "ex", {"answers": {}})
        assert store.progress.spelling("alice  doe") == "Alice Doe"
        assert store.progress.spelling("ALICE DOE") == "Alice Doe"
        assert store.progress.spelling("Alice Doe") == "Alice Doe"
        assert store.progress.spelling("Bob") == "Bob"
