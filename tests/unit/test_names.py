"""Students' names: what the names dialog and --student/--partner accept."""

import re
import unicodedata

import pytest
from hypothesis import given
from hypothesis import strategies as st

from workbench.labs.names import NameProblem, check_pair, clean_name, scripts_of


def test_names_are_trimmed_and_the_partner_is_optional():
    assert check_pair("  Ana Lopez ", "") == ("Ana Lopez", "")
    assert check_pair("ana", " ben ") == ("ana", "ben")


@pytest.mark.parametrize(
    ("student", "partner", "message"),
    [
        ("", "", "the student's name is empty"),
        ("   ", "ben", "the student's name is empty"),
        ("x" * 41, "", "longer than 40 characters"),
        ("ana\x1b[31m", "", "control characters"),
        ("ana", "ANA", "the partner is the student"),
        ("ana", "b\tb", "partner's name has control characters"),
    ],
)
def test_bad_names_are_refused_with_the_reason(student, partner, message):
    with pytest.raises(NameProblem, match=message.replace("(", r"\(")):
        check_pair(student, partner)


def test_names_are_normalised_to_nfkc():
    assert check_pair("Ａｎａ", "Ｂｅｎ") == ("Ana", "Ben")  # full-width letters
    assert check_pair("Jose\u0301", "") == ("José", "")  # a combining accent composed
    assert check_pair("Иван Петров", "山田 太郎") == ("Иван Петров", "山田 太郎")
    assert check_pair("やまだ Taro", "Δημήτρης") == ("やまだ Taro", "Δημήτρης")
    assert check_pair("Ana\u00a0Lopez", "") == ("Ana Lopez", "")  # a no-break space


@pytest.mark.parametrize(
    ("name", "message"),
    [
        ("аlice", "mixes letters of different scripts (Cyrillic, Latin)"),  # Cyrillic а
        ("bοb", "mixes letters of different scripts (Greek, Latin)"),  # Greek ο
        ("ana\u200b", "invisible formatting characters (U+200B at position 4)"),
        ("ana\u200d", "invisible formatting characters (U+200D"),
        ("\u2066ana\u2069", "invisible formatting characters (U+2066 at position 1)"),
        ("an\u00ada", "invisible formatting characters (U+00AD"),  # soft hyphen
        ("ana\ufe0f", "invisible character (U+FE0F"),
        ("ana\u2800", "invisible character (U+2800"),
        ("ana\u2028b", "line separators"),
        ("ana\ue000", "private-use characters"),
        ("ana  lopez", "two spaces in a row"),
    ],
)
def test_look_alike_and_invisible_names_are_refused(name, message):
    with pytest.raises(NameProblem, match=re.escape(message)):
        check_pair(name)
    with pytest.raises(NameProblem, match=re.escape(message)):
        check_pair("zoe", name)


@given(st.text(max_size=50))
def test_any_text_is_a_clean_name_or_a_reason(text):
    try:
        name = clean_name(text, "the name", 40)
    except NameProblem as exc:
        assert str(exc).startswith("the name ")
    else:
        assert name == unicodedata.normalize("NFKC", name) == name.strip()
        assert clean_name(name, "the name", 40) == name
        assert not any(unicodedata.category(c) in ("Cc", "Cf", "Co", "Cn") for c in name)
        assert len(scripts_of(name) - {"LATIN", "HAN", "HIRAGANA", "KATAKANA", "HANGUL",
                                       "BOPOMOFO"}) <= 1  # fmt: skip


@pytest.mark.parametrize(
    "control",
    ["\u202a", "\u202b", "\u202c", "\u202d", "\u202e", "\u2066", "\u2067", "\u2068", "\u2069",
     "\u200e", "\u200f", "\u061c"],
)  # fmt: skip
def test_every_bidi_control_is_refused_in_a_name(control):
    with pytest.raises(NameProblem, match=rf"U\+{ord(control):04X} at position 4"):
        check_pair(f"ana{control}nim")
